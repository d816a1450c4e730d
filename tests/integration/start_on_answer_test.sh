#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-haptic --start-on-answer (issue 17 item 6): a scripted path is
# played from the server's first answer, so none of it goes out before the
# server's command reader has matched the client's writer (some 0.1-0.5 s
# after the client saw the scene on a busy machine; a lab seat whose first
# half second was lost met the gallbladder with the probe already 8 mm
# inside it, and its physics did a quarter less work than the seat alone's
# for the whole run: docs/numerics.md §11.8). A real server (default
# scene) and the client on loopback; the probe goes up and down 20 mm above
# the kidney every 0.2 s for 2.4 s (240 mm of path), and the server keeps
# from hearing it at first: tool 0 is assigned to station alice, the client
# is station bob (its commands refused, never answered), and about 1 s
# after the client starts the tool is assigned to bob (viscera-control):
#  - with --start-on-answer the client says its path started after 0.5 s
#    or more of its loop, its force log holds the path's first pose until
#    then, and the server's own tool-tip path length (PALPATION
#    path_length) is the whole 0.240 m (within 2 %): the server saw the
#    path from its first pose;
#  - without it (the case exercised) the server saw at most 0.2 m of it;
#  - a tool the scene does not have (the server never answers): after
#    --wait-server 1 s the path starts anyway, with a warning.
# No wall-clock check.
# usage: start_on_answer_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-196}"
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do [ -s "$f" ] && { echo "--- $f"; tail -8 "$f"; }; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
TRAJ="$OUT/updown.traj"
awk 'BEGIN { for (i = 0; i <= 12; i++) printf "%.1f 0.012 0.004 %s\n", 0.2 * i, i % 2 ? "0.05" : "0.07" }' > "$TRAJ"
CTL=("$BUILD/client/control/viscera-control" --domain "$DOMAIN" --wait 15)
run() { # NAME PARTITION CLIENT-OPTIONS...: a server, tool 0 for alice, the client as bob, tool 0 to bob after 1 s
  local name=$1 part=$2 srv cli
  shift 2
  "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --domain "$DOMAIN" --partition "$part" \
    > "$OUT/$name-server.out" 2> "$OUT/$name-server.log" &
  srv=$!; pids+=("$srv")
  "${CTL[@]}" --partition "$part" assign 0 alice > "$OUT/$name-ctl1.log" 2>&1 || fail "$name: assign to alice failed"
  "$BUILD/client/haptic/viscera-haptic" --domain "$DOMAIN" --partition "$part" --trajectory "$TRAJ" --station bob \
    --force-csv "$OUT/$name-force.csv" "$@" > "$OUT/$name-haptic.out" 2> "$OUT/$name-haptic.log" &
  cli=$!; pids+=("$cli")
  sleep 1
  "${CTL[@]}" --partition "$part" assign 0 bob > "$OUT/$name-ctl2.log" 2>&1 || fail "$name: assign to bob failed"
  wait "$cli" || fail "$name: haptic client failed"
  kill -INT "$srv"; wait "$srv" || fail "$name: server exited with an error"
}
path_len() { sed -n 's/^PALPATION tool=[^ ]* .*path_length=\([0-9.]*\).*/\1/p' "$OUT/$1-server.out" | head -1; }

run answer soa/answer --start-on-answer
start=$(sed -n 's/^haptic: path started at \([0-9.]*\) s of the loop (--start-on-answer)$/\1/p' "$OUT/answer-haptic.log")
[ -n "$start" ] || fail "the client did not say where the path started"
awk -v s="$start" 'BEGIN { exit !(s >= 0.5) }' || fail "the path started at $start s: before the server could answer"
# Every tick before the start at the path's first pose (z = 0.07), and the path moving after it.
awk -F, -v s="$start" 'NR > 1 && $1 + 0 < s - 0.0005 && ($4 + 0 != 0.07) { bad++ } NR > 1 && $1 + 0 > s + 0.1 && $4 + 0 < 0.069 { moved++ }
  END { exit !(bad == 0 && moved > 0) }' "$OUT/answer-force.csv" ||
  fail "the force log does not hold the first pose until $start s, then move"
len=$(path_len answer)
run launch soa/launch
len0=$(path_len launch)
echo "path started at $start s of the client's loop; the server's tool-tip path $len m of 0.240 (without --start-on-answer ${len0:-none} m)"
awk -v l="${len:-0}" 'BEGIN { exit !(l > 0.2352 && l < 0.2448) }' ||
  fail "the server's tool-tip path is ${len:-none} m, not the path's 0.240 m: part of it was lost"
awk -v l="${len0:-1}" 'BEGIN { exit !(l < 0.2) }' ||
  fail "without --start-on-answer the server still saw ${len0:-none} m of 0.240: the case is not exercised"

run silent soa/silent --start-on-answer --tool 3 --wait-server 1
grep -q "^haptic: warning: no answer from the server within 1.0 s: the path starts without one" "$OUT/silent-haptic.log" ||
  fail "no warning when the server never answers"
grep -q "^haptic: path started at " "$OUT/silent-haptic.log" || fail "the path did not start without an answer"
echo "PASS: the path plays from the server's first answer; without one it starts after --wait-server with a warning"
