#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
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
# Steps wait (60 s at most, a safety stop) for events: the trainee's ticks
# before the impostor starts, the impostor's end before the trainee and the
# server stop, a viewer frame at the server's last frame before the viewer
# stops; no wall-clock schedule or --duration (issue 15.6).
rows() { local n; n=$(wc -l < "$1" 2>/dev/null) || n=0; echo $((n > 0 ? n - 1 : 0)); }
for role in impostor server; do
  D="$OUT/$role"; mkdir -p "$D"; PART=hardnet/imp_$role
  "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $PART \
    --final-mesh "$D/server.obj" > "$D/server.out" 2> "$D/server.log" & SRV=$!; PIDS+=($SRV)
  "$BUILD/client/haptic/viscera-haptic" --partition $PART --tool 0 --trajectory "$OUT/trainee.traj" --duration 90 \
    --wait-server 60 --quiet --force-csv "$D/force.csv" > "$D/haptic.out" 2> "$D/haptic.log" & HAP=$!; PIDS+=($HAP)
  for _ in $(seq 600); do [ "$(rows "$D/force.csv")" -ge 200 ] && break; sleep 0.1; done
  "$BUILD/tests/integration/impostor" run "$VISCERA_DOMAIN" $PART $role 4 > "$D/impostor.out" 2> "$D/impostor.log" &
  IMP=$!; PIDS+=($IMP)
  sleep 1 # the viewer joins while the impostor writes
  "$BUILD/client/viewer/viscera-viewer" --partition $PART --out "$D/frames" --interval-ms 0 --dump-mesh "$D/viewer.obj" \
    > "$D/viewer.out" 2> "$D/viewer.log" & VIEWER=$!; PIDS+=($VIEWER)
  wait $IMP || fail "$role: impostor failed"
  kill -INT $HAP; wait $HAP || fail "$role: haptic client failed"
  kill -INT $SRV; wait $SRV || fail "$role: server failed"
  # The viewer has applied the server's last frame: a frame written on
  # SIGUSR1 (interval 0) names it.
  last=$(head -1 "$D/server.obj" | sed -n 's/.* frame \([0-9]*\)$/\1/p')
  for _ in $(seq 300); do
    kill -USR1 $VIEWER
    sleep 0.2
    [ "$(tail -n 1 "$D/frames/frames.csv" 2>/dev/null | cut -d, -f5)" = "${last:-x}" ] && break
  done
  kill -INT $VIEWER; wait $VIEWER || fail "$role: viewer failed"
  cat "$D/impostor.out"
  "$BUILD/tests/integration/impostor" check "$D/force.csv" "$D/haptic.out" "$D/viewer.out" || fail "$role: check"
  [ "$(head -1 "$D/server.obj")" = "$(head -1 "$D/viewer.obj")" ] || fail "$role: viewer not at the server's last frame"
  "$BUILD/tests/integration/obj_compare" "$D/server.obj" "$D/viewer.obj" 5.2e-6 || fail "$role: viewer mesh differs"
done
echo PASS
