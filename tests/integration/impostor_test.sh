#!/usr/bin/env bash
# Issue 15.2: an impostor participant (not the seat's server) publishes
# ContactFeedback for tool 0 (4 N into the tissue) and a forged MeshState
# and MeshDelta for organ 0 while a trainee holds its probe still in free
# space and a viewer joins late. The trainee's force log never shows a
# force, the viewer ends on the server's mesh (not the forged organ), and
# both clients count the ignored samples (impostor check, obj_compare).
# Run twice: the impostor announcing role "impostor", then claiming
# "server" (it still never wrote SceneInfo).
# usage: impostor_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
A=0.000,0.004,0.070
printf '# holds still above the kidney\n0 %s\n100 %s\n' "${A//,/ }" "${A//,/ }" > "$OUT/trainee.traj"
for role in impostor server; do
  D="$OUT/$role"; mkdir -p "$D"; PART=hardnet/imp_$role
  "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $PART --duration 7 \
    --final-mesh "$D/server.obj" > "$D/server.out" 2> "$D/server.log" & SRV=$!; PIDS+=($SRV)
  "$BUILD/client/haptic/viscera-haptic" --partition $PART --tool 0 --trajectory "$OUT/trainee.traj" --duration 5 \
    --wait-server 20 --quiet --force-csv "$D/force.csv" > "$D/haptic.out" 2> "$D/haptic.log" & HAP=$!; PIDS+=($HAP)
  sleep 1
  "$BUILD/tests/integration/impostor" run "$VISCERA_DOMAIN" $PART $role 4 > "$D/impostor.out" 2> "$D/impostor.log" &
  IMP=$!; PIDS+=($IMP)
  sleep 1
  "$BUILD/client/viewer/viscera-viewer" --partition $PART --out "$D/frames" --interval-ms 0 --dump-mesh "$D/viewer.obj" \
    > "$D/viewer.out" 2> "$D/viewer.log" & VIEWER=$!; PIDS+=($VIEWER)
  wait $IMP || fail "$role: impostor failed"
  wait $HAP || fail "$role: haptic client failed"
  wait $SRV || fail "$role: server failed"
  sleep 0.5
  kill -INT $VIEWER; wait $VIEWER || fail "$role: viewer failed"
  cat "$D/impostor.out"
  "$BUILD/tests/integration/impostor" check "$D/force.csv" "$D/haptic.out" "$D/viewer.out" || fail "$role: check"
  [ "$(head -1 "$D/server.obj")" = "$(head -1 "$D/viewer.obj")" ] || fail "$role: viewer not at the server's last frame"
  "$BUILD/tests/integration/obj_compare" "$D/server.obj" "$D/viewer.obj" 5.2e-6 || fail "$role: viewer mesh differs"
done
echo PASS
