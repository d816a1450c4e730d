# SPDX-License-Identifier: Apache-2.0
# shellcheck shell=bash
# Sourced by lab.sh and load_bench.sh. One server process running several
# seats (viscera-server --seats) writes one log; split_seat_log cuts it into
# the per-seat files one server per seat would have written: each seat's
# figures follow its "server: seat 'PREFIX/seatNN' (k of N):" line (stderr)
# and its "SEAT partition=PREFIX/seatNN ..." line (stdout); lines before the
# first are the process's own and are not copied.
# split_seat_log LOG OUT_DIR PREFIX SUFFIX: writes OUT_DIR/seatNN-SUFFIX.
split_seat_log() {
  awk -v out="$2" -v pre="$3" -v suf="$4" '
    $0 ~ "^server: seat ." pre "/seat[0-9]+. \\([0-9]+ of [0-9]+\\):$" { n = $3; sub(/.*\//, "", n); sub(/[^a-z0-9]+$/, "", n)
      f = out "/" n "-" suf; next }
    $0 ~ "^SEAT partition=" pre "/seat[0-9]+ " { n = $2; sub(/.*\//, "", n); f = out "/" n "-" suf; next }
    f { print > f }' "$1"
}
