#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The instructor's commands to a running seat (issue 7), real processes on
# loopback: pause freezes simulated time (the server's own clock stands still
# from the pause to the resume, and the viewer's frames stop advancing) and
# resume continues it; a reset restarts the scene with a new topology
# version that a viewer follows exactly (its mesh equals the server's final
# mesh); new material is applied (the server says so) and a bad organ id is
# refused with a reason. Judged by the applied controls' simulated times in
# the recording (rec_tools) and the viewer's own frames, never by
# wall-clock windows (issue 15.6): each step waits for the answer or the
# frames it needs (60 s at most, a safety stop).
# usage: control_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
PART=test/control
CTL=("$BUILD/client/control/viscera-control" --partition $PART --wait 60)
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $PART \
  --final-mesh "$OUT/server.obj" > "$OUT/server.out" 2> "$OUT/server.log" & SRV=$!; PIDS+=($SRV)
"$BUILD/client/recorder/viscera-recorder" --partition $PART --out "$OUT/session.db" --quiet \
  > "$OUT/recorder.out" 2> "$OUT/recorder.log" & REC=$!; PIDS+=($REC)
"$BUILD/client/viewer/viscera-viewer" --partition $PART --out "$OUT/frames" --interval-ms 200 \
  --dump-mesh "$OUT/viewer.obj" > "$OUT/viewer.out" 2> "$OUT/viewer.log" & VIEW=$!; PIDS+=($VIEW)
# frames N: until the viewer has written N frames showing a mesh; 60 s at most.
shown() { awk -F, 'NR > 1 && $4 >= 0 { n++ } END { print n + 0 }' "$OUT/frames/frames.csv" 2>/dev/null || echo 0; }
frames() { for _ in $(seq 600); do [ "$(shown)" -ge "$1" ] && return 0; sleep 0.1; done; return 1; }
frames 2 || fail "the viewer never showed the scene"
"${CTL[@]}" pause > "$OUT/ctl.log" 2>&1 || fail "pause not applied"
# Paused: the viewer's frames written after the answer end with 3 in a row
# (its own frame counter) showing one simulated time; resumed: a later frame
# shows a later one.
N0=$(shown)
tail_run() { awk -F, -v n0="$N0" 'NR > 1 && $4 >= 0 && ++k > n0 { if ($4 == v) n++; else { v = $4; n = 1 } }
  END { print n + 0, v + 0 }' "$OUT/frames/frames.csv"; }
for _ in $(seq 600); do read -r run frozen < <(tail_run); [ "$run" -ge 3 ] && break; sleep 0.1; done
[ "$run" -ge 3 ] || fail "the viewer's frames did not stop advancing while paused"
"${CTL[@]}" resume >> "$OUT/ctl.log" 2>&1 || fail "resume not applied"
N0=$(shown)
for _ in $(seq 600); do read -r run now < <(tail_run); awk -v a="$now" -v b="$frozen" 'BEGIN { exit !(a > b) }' && break; sleep 0.1; done
awk -v a="$now" -v b="$frozen" 'BEGIN { printf "viewer: paused at simulated %.4f s, then %.4f s after the resume\n", b, a; exit !(a > b) }' \
  || fail "simulated time did not advance after the resume"
"${CTL[@]}" material 0 60 -1 -1 -1 >> "$OUT/ctl.log" 2>&1 || fail "material not applied"
if "${CTL[@]}" material 7 60 -1 -1 -1 >> "$OUT/ctl.log" 2>&1; then fail "a bad organ id was applied"; fi
grep -q "refused: .*organ id out of range" "$OUT/ctl.log" || fail "bad organ id not refused with its reason"
"${CTL[@]}" reset >> "$OUT/ctl.log" 2>&1 || fail "reset not applied"
cat "$OUT/ctl.log"
frames $(($(shown) + 3)) || fail "the viewer stopped writing frames after the reset"
kill -INT $SRV; wait $SRV || fail "server exited with an error"
# The viewer has what the server published last: a few more of its frames.
frames $(($(shown) + 3)) || fail "the viewer stopped writing frames"
for p in $VIEW $REC; do kill -INT $p; wait $p || fail "viewer or recorder exited with an error"; done
PIDS=()
"$BUILD/tests/integration/rec_tools" "$OUT/session.db" > "$OUT/rec.txt" || fail "rec_tools failed"
grep '^EVENT CONTROL_APPLIED ' "$OUT/rec.txt"
sim_of() { grep "^EVENT CONTROL_APPLIED .* $1" "$OUT/rec.txt" | head -1 | tr ' ' '\n' | sed -n 's/^sim=//p'; }
t_pause=$(sim_of "paused"); t_resume=$(sim_of "resumed"); t_mat=$(sim_of "material: stiffness") # 0: a rebuild restarts the clock
[ -n "$t_pause" ] && [ -n "$t_resume" ] && [ -n "$t_mat" ] || fail "pause, resume or material missing from the recording"
# Pause: the server's simulated time stood still until the resume (one step
# at most: the pause is applied at a step's start), and the viewer's frozen
# frames showed it (the last sample published before the pause); after the
# resume the viewer saw a simulated time beyond it.
awk -v p="$t_pause" -v r="$t_resume" -v f="$frozen" -v a="$now" 'BEGIN { printf "server: paused at simulated %.4f s, resumed at %.4f s\n", p, r
  exit !(r - p <= 0.0011 && r >= p && f <= p + 0.0011 && f > p - 0.1 && a > p + 0.0011) }' || fail "pause did not freeze simulated time"
# The material change and the reset each rebuilt the scene: topology version
# 2 at both ends, same positions.
grep -q "topology 2 " "$OUT/server.obj" || fail "the rebuilds did not publish new topology versions"
"$BUILD/tests/integration/obj_compare" "$OUT/server.obj" "$OUT/viewer.obj" 1e-5 || fail "the viewer did not follow the reset"
grep -q "material: stiffness 60 N/m" "$OUT/server.log" || fail "the material change is not in the server log"
echo "frames: $(shown), last simulated time seen $(tail -n 1 "$OUT/frames/frames.csv" | cut -d, -f4) s"
echo PASS
