#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Fault tolerance of a seat (issue 7), with real processes on loopback:
#   1. killing the recorder (-9) and one viewer (-9) mid-session disturbs
#      nothing: the haptic client keeps its contact force, the server and
#      the other viewer keep going;
#   2. a stalled viewer (SIGSTOP for 3 s) never blocks the server: the haptic
#      client never loses it and keeps its contact force;
#   3. the server is killed (-9) while the probe presses: the haptic client
#      reports "server lost"; a restarted server resumes from its checkpoint
#      (the dent is still there, simulated time continues) where a server
#      without the checkpoint starts from rest;
#   4. a damaged checkpoint is refused with a message and the server starts
#      from rest.
# usage: fault_tolerance_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
PART=test/faults
common=(--partition $PART)
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -CONT "$p" 2>/dev/null || true; kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do echo "--- $f"; tail -6 "$f"; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
SRV="$BUILD/server/viscera-server"; SCENE="$SRC/assets/scenes/default.yaml"; CK="$OUT/seat.ckpt"

"$SRV" --scene "$SCENE" "${common[@]}" --checkpoint "$CK" --checkpoint-every 0.25 > "$OUT/server1.out" 2> "$OUT/server1.log" &
SERVER=$!; PIDS+=($SERVER)
"$BUILD/client/recorder/viscera-recorder" "${common[@]}" --out "$OUT/rec.db" --quiet > "$OUT/recorder.log" 2>&1 &
REC=$!; PIDS+=($REC)
"$BUILD/client/viewer/viscera-viewer" "${common[@]}" --out "$OUT/frames_a" --interval-ms 200 > "$OUT/viewer_a.log" 2>&1 &
VA=$!; PIDS+=($VA)
"$BUILD/client/viewer/viscera-viewer" "${common[@]}" --out "$OUT/frames_b" --interval-ms 200 > "$OUT/viewer_b.log" 2>&1 &
VB=$!; PIDS+=($VB)
"$BUILD/client/viewer/viscera-viewer" "${common[@]}" --out "$OUT/frames_c" --interval-ms 200 > "$OUT/viewer_c.log" 2>&1 &
VC=$!; PIDS+=($VC)
# Press at t = 1.5 s and hold to the end (30 s trajectory, cut by --duration).
"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/push_hold_kidney.traj" "${common[@]}" \
  --duration 12 --force-csv "$OUT/force.csv" > "$OUT/haptic.out" 2> "$OUT/haptic.log" & HAP=$!; PIDS+=($HAP)
# Judged by events and the client's own ticks, never by wall-clock windows
# (issue 15.6): the steps wait for the events they need.
await() { for _ in $(seq 600); do grep -q -- "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done; return 1; }
rows() { local n; n=$(wc -l < "$OUT/force.csv"); echo $((n > 0 ? n - 1 : 0)); }
await "$OUT/server1.log" "ST crossed up" || fail "the press never reached the sound threshold"
sleep 0.5            # pressing
# The force log's rows (ticks) written from here to the stall's end are the
# ticks these events could disturb (stdio buffering makes the first row a
# little early: still pressing).
R0=$(rows)
# 1. Recorder and a viewer vanish.
kill -9 $REC $VA; wait $REC $VA 2>/dev/null || true
# 2. Another viewer stalls for 3 s.
kill -STOP $VB; sleep 3; kill -CONT $VB
sleep 0.5
R1=$(rows)
kill -0 $SERVER || fail "the server died while clients vanished or stalled"
kill -0 $VC || fail "an unaffected viewer died"
kill -0 $VB || fail "the stalled viewer did not survive"
# A server blocked by a stalled reliable reader would stop stepping for up
# to the writers' max blocking time (1 s) per write, and its feedback would
# stop: the haptic client would render zero force for about 1000 ticks in a
# row. Through both events >= 75 % of its ticks felt the organ and no run
# without force reached 500 ticks (force_check hold; false "server lost"
# blips of a starved client stay well below both).
"$BUILD/tests/integration/force_check" hold "$OUT/force.csv" "$R0" "$R1" \
  || fail "contact force was disturbed by a killed or stalled client"

# 3. The server dies mid-press; a restart resumes from the checkpoint.
kill -9 $SERVER; wait $SERVER 2>/dev/null || true
[ -s "$CK" ] || fail "no checkpoint was written"
await "$OUT/haptic.log" "server lost" || fail "the haptic client did not report the lost server"
kill -INT $HAP 2>/dev/null || true; wait $HAP 2>/dev/null || true
"$SRV" --scene "$SCENE" "${common[@]}" --checkpoint "$CK" --duration 0.03 --final-mesh "$OUT/resumed.obj" \
  > "$OUT/server2.out" 2> "$OUT/server2.log" || fail "the restarted server failed"
grep -q "resumed from checkpoint" "$OUT/server2.log" || fail "the restarted server did not resume from its checkpoint"
t_resumed=$(sed -n 's/.*resumed from checkpoint .* at t = \([0-9.]*\) s.*/\1/p' "$OUT/server2.log")
echo "resumed at simulated t = $t_resumed s"
awk -v t="$t_resumed" 'BEGIN { exit !(t > 2.0) }' || fail "resumed simulated time $t_resumed s is not where the session was"
"$SRV" --scene "$SCENE" --partition test/faults-fresh --duration 0.03 --final-mesh "$OUT/fresh.obj" \
  > "$OUT/server3.out" 2> "$OUT/server3.log" || fail "a fresh server failed"
dent=$("$BUILD/tests/integration/obj_compare" "$OUT/resumed.obj" "$OUT/fresh.obj" 1 | sed -n 's/.*max_diff=\([0-9.e+-]*\).*/\1/p')
echo "resumed vs fresh mesh: max difference $dent m"
# The kidney's home springs pull a dent back within about 10 ms (omega ~ 630
# rad/s), so 30 ms after the restart most of it is gone; what is left (0.7 mm
# seen) still tells a restored state from a fresh one, which is exactly rest
# (the same scene run the same way: a difference of 0).
awk -v d="${dent:-0}" 'BEGIN { exit !(d > 0.0002) }' || fail "the resumed organ is at rest: the checkpoint state was not restored"

# 4. A damaged checkpoint: refused, fresh start, exit 0.
head -c 1000 "$CK" > "$OUT/damaged.ckpt"
"$SRV" --scene "$SCENE" --partition test/faults-fresh --checkpoint "$OUT/damaged.ckpt" --duration 0.03 \
  > "$OUT/server4.out" 2> "$OUT/server4.log" || fail "a damaged checkpoint stopped the server"
grep -q "damaged\|not a viscera checkpoint" "$OUT/server4.log" || fail "the damaged checkpoint was not reported"
grep -q "resumed from checkpoint" "$OUT/server4.log" && fail "the server resumed from a damaged checkpoint"
for p in $VB $VC; do kill -INT $p 2>/dev/null || true; wait $p 2>/dev/null || true; done
PIDS=()
echo PASS
