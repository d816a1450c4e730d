#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# deploy/lab.sh --one-server with many seats (ten, without trainees or
# viewers), ended by --duration: the one server's log is split into one log
# per seat, and each seat's log holds that seat's figures and no other's.
# The server writes its per-seat figures to stderr (unbuffered) and its
# SEAT/SUMMARY lines to stdout (block-buffered into the same file): with more
# than a buffer's worth of stdout (a five-seat lab already), a flush in the
# middle of one seat's stdout let the next seat's stderr header land inside a
# line, so the split gave that seat's figures to the seat before (the lab's
# summary then showed seat 4 with seat 5's step time and seat 5 with none).
# Asserts: exactly one step-time line and one SUMMARY line in every
# seatNN-server.log, each SUMMARY's step_us_median equal to that log's own
# step time median, a summary line with a step time for every seat, every
# line of the one log starts where a line of the server starts, and the one
# log lists the seats one after the other (header, figures, SEAT lines).
# usage: lab_one_server_logs_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
# shellcheck source=lab_checks.sh
. "$(dirname "$0")/lab_checks.sh"
L=""
cleanup() { [ -z "$L" ] || kill -TERM "$L" 2>/dev/null || true; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  for f in "$OUT"/*.out; do [ -f "$f" ] && { echo "--- $f"; tail -15 "$f"; }; done >&2
  exit 1
}
rm -rf "$OUT"; mkdir -p "$OUT"
SEATS=10
launch_lab L "$OUT/lab.out" --out "$OUT/l" --one-server --seats $SEATS --viewers 0 --no-record --duration 4
for ((t = 0; t < 600; t++)); do kill -0 "$L" 2>/dev/null || break; sleep 0.1; done
kill -0 "$L" 2>/dev/null && fail "lab.sh still running 60 s after its --duration"
st=0; wait "$L" || st=$?
L=""
cat "$OUT/lab.out"
[ "$st" = 0 ] || fail "the lab exited with $st"
LOG="$OUT/l/seats-server.log"
[ -f "$LOG" ] || fail "no seats-server.log"
# Every line begins as the server begins its lines (a seat header inside a
# line is what broke the split).
bad=$(grep -c -v -E '^(server|viscera-server|SEAT|SUMMARY|INTAKE|PUBLISHED|PALPATION|TOOL|TASK|OBJECT|scene|  organ|CPU|warning)' "$LOG" || true)
[ "$bad" = 0 ] || fail "$bad line(s) of $LOG begin inside another line: $(grep -v -E '^(server|viscera-server|SEAT|SUMMARY|INTAKE|PUBLISHED|PALPATION|TOOL|TASK|OBJECT|scene|  organ|CPU|warning)' "$LOG" | head -3)"
# Seat by seat: seat k's header, then its SEAT line, before seat k+1's
# header. A split that depends on where a buffer happened to be flushed is
# what went wrong; this order makes it independent of that.
order=$(grep -o -E "^server: seat 'lab/seat[0-9]+'|^SEAT partition=lab/seat[0-9]+" "$LOG" |
  sed -E "s/^server: seat 'lab\/(seat[0-9]+)'/H \1/; s/^SEAT partition=lab\/(seat[0-9]+)/S \1/" | tr '\n' ' ')
want=""
for i in $(seq 1 $SEATS); do want+="$(printf 'H seat%02d S seat%02d ' "$i" "$i")"; done
[ "$order" = "$want" ] || fail "the one log is not seat by seat: $order"
for i in $(seq 1 $SEATS); do
  s=$(printf 'seat%02d' "$i")
  f="$OUT/l/$s-server.log"
  [ -f "$f" ] || fail "no $s-server.log"
  n=$(grep -c '^server: [0-9]* steps, step time median' "$f" || true)
  [ "$n" = 1 ] || fail "$s-server.log has $n step-time lines, expected its own one"
  n=$(grep -c '^SUMMARY steps=' "$f" || true)
  [ "$n" = 1 ] || fail "$s-server.log has $n SUMMARY lines, expected 1"
  own=$(sed -n 's/^server: [0-9]* steps, step time median \([0-9.]*\) us.*/\1/p' "$f")
  sum=$(sed -n 's/^SUMMARY .* step_us_median=\([0-9.]*\).*/\1/p' "$f")
  [ "$own" = "$sum" ] || fail "$s-server.log: step time median $own but SUMMARY step_us_median=$sum (another seat's figures)"
  grep -Eq "^  $s: frames 0, step time median $own us" "$OUT/lab.out" ||
    fail "the lab's summary line for $s does not carry its step time $own us"
done
echo PASS
