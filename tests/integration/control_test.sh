#!/usr/bin/env bash
# The instructor's commands to a running seat (issue 7), real processes on
# loopback: pause freezes simulated time (the viewer's frames stop advancing)
# and resume continues it; a reset restarts the scene with a new topology
# version that a viewer follows exactly (its mesh equals the server's final
# mesh); new material is applied (the server says so) and a bad organ id is
# refused with a reason. usage: control_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
PART=test/control
CTL=("$BUILD/client/control/viscera-control" --partition $PART --wait 8)
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $PART --duration 14 \
  --final-mesh "$OUT/server.obj" > "$OUT/server.out" 2> "$OUT/server.log" & SRV=$!; PIDS+=($SRV)
"$BUILD/client/viewer/viscera-viewer" --partition $PART --out "$OUT/frames" --interval-ms 200 --duration 13 \
  --dump-mesh "$OUT/viewer.obj" > "$OUT/viewer.out" 2> "$OUT/viewer.log" & VIEW=$!; PIDS+=($VIEW)
sleep 1.5
"${CTL[@]}" pause > "$OUT/ctl.log" 2>&1 || fail "pause not applied"
sleep 2
"${CTL[@]}" resume >> "$OUT/ctl.log" 2>&1 || fail "resume not applied"
sleep 1
"${CTL[@]}" material 0 60 -1 -1 -1 >> "$OUT/ctl.log" 2>&1 || fail "material not applied"
if "${CTL[@]}" material 7 60 -1 -1 -1 >> "$OUT/ctl.log" 2>&1; then fail "a bad organ id was applied"; fi
grep -q "refused: .*organ id out of range" "$OUT/ctl.log" || fail "bad organ id not refused with its reason"
"${CTL[@]}" reset >> "$OUT/ctl.log" 2>&1 || fail "reset not applied"
cat "$OUT/ctl.log"
wait $SRV || fail "server exited with an error"
wait $VIEW || fail "viewer failed"
PIDS=()
# Pause: frames written while paused (after the command's answer, before
# resume) all show one simulated time; after resume it advances again.
awk -F, 'NR>1 { print $3, $4 }' "$OUT/frames/frames.csv" > "$OUT/sim_times.txt"
paused=$(grep -c "" "$OUT/sim_times.txt")
# The viewer's wall clock starts at its own start; find frames whose sim time
# repeats for >= 1.5 s of wall time (the pause) and frames after it that advance.
awk '{ w=$1; t=$2; if (t == prev) { run += w - pw } else { if (run > best) best = run; run = 0 } prev = t; pw = w }
     END { if (run > best) best = run; printf "longest frozen simulated time: %.2f s of wall time\n", best / 1000;
           exit !(best >= 1500) }' "$OUT/sim_times.txt" || fail "pause did not freeze simulated time"
last_t=$(tail -n 1 "$OUT/sim_times.txt" | cut -d' ' -f2)
# The material change and the reset each rebuilt the scene: topology version
# 2 at both ends, same positions.
grep -q "topology 2 " "$OUT/server.obj" || fail "the rebuilds did not publish new topology versions"
"$BUILD/tests/integration/obj_compare" "$OUT/server.obj" "$OUT/viewer.obj" 1e-5 || fail "the viewer did not follow the reset"
grep -q "material: stiffness 60 N/m" "$OUT/server.log" || fail "the material change is not in the server log"
echo "frames: $paused, last simulated time seen $last_t s"
echo PASS
