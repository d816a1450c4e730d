#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Topology streaming end to end: the server runs the adaptive kidney
# (assets/scenes/kidney_adaptive.yaml), a scripted probe presses in and holds
# (push_hold_kidney.traj), the mesh refines under it (a new MeshState keyframe
# with topology_version 1 and more vertices, EVENT_TOPOLOGY_CHANGED). A viewer
# running from the start and a viewer started after the refinement both end
# on the server's final mesh: same frame (topology, keyframe, frame in the
# OBJ header), same triangles, positions within half a quantization step, and
# the refined vertex count. The recording holds a MeshState keyframe for
# every topology version from 0 up, more than one version.
# usage: topology_stream_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-80}"
common=(--domain "$DOMAIN" --partition test/topology)
rm -rf "$OUT"; mkdir -p "$OUT"
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done' EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log "$OUT"/*.out; do echo "--- $f"; tail -5 "$f"; done >&2; exit 1; }
# Polls a file for a pattern (a loaded machine may take a while).
wait_for() { for _ in $(seq 1 300); do grep -q "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done; return 1; }

"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/kidney_adaptive.yaml" "${common[@]}" \
  --final-mesh "$OUT/server.obj" >"$OUT/server.out" 2>"$OUT/server.log" & SERVER=$!; pids+=($SERVER)
have_rec=0
if [ -x "$BUILD/client/recorder/viscera-recorder" ] && [ -x "$BUILD/tests/integration/rec_topology" ]; then
  "$BUILD/client/recorder/viscera-recorder" "${common[@]}" --out "$OUT/session.db" --scene topology \
    >"$OUT/recorder.out" 2>"$OUT/recorder.log" & REC=$!; pids+=($REC); have_rec=1
fi
"$BUILD/client/viewer/viscera-viewer" "${common[@]}" --out "$OUT/frames_early" --interval-ms 500 \
  --dump-mesh "$OUT/viewer_early.obj" >"$OUT/viewer_early.out" 2>"$OUT/viewer_early.log" & V1=$!; pids+=($V1)
wait_for "$OUT/server.log" "running on domain" || fail "server did not start"
# The recording must start at topology 0: the recorder reads MeshState before the probe moves.
[ $have_rec = 1 ] && { wait_for "$OUT/recorder.log" "recording topic viscera_MeshState" || fail "recorder never saw MeshState"; }
"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/push_hold_kidney.traj" "${common[@]}" \
  --quiet >"$OUT/haptic.out" 2>"$OUT/haptic.log" & HAPTIC=$!; pids+=($HAPTIC)
wait_for "$OUT/server.log" "topology 1:" || fail "the kidney never refined under the probe"
grep "topology" "$OUT/server.log"
"$BUILD/client/viewer/viscera-viewer" "${common[@]}" --out "$OUT/frames_late" --interval-ms 0 \
  --dump-mesh "$OUT/viewer_late.obj" >"$OUT/viewer_late.out" 2>"$OUT/viewer_late.log" & V2=$!; pids+=($V2)
wait_for "$OUT/viewer_late.out" "camera fixed" || fail "late viewer got no keyframe"
grep "organ 0" "$OUT/viewer_late.out"
sleep 1
kill -INT $SERVER; wait $SERVER || fail "server exited with an error"
sleep 0.5
kill -INT $V1 $V2; wait $V1 || fail "early viewer exited with an error"; wait $V2 || fail "late viewer exited with an error"
[ $have_rec = 1 ] && { kill -INT $REC; wait $REC || fail "recorder exited with an error"; }
kill -INT $HAPTIC 2>/dev/null || true; wait $HAPTIC 2>/dev/null || true
pids=()

[ -f "$OUT/server.obj" ] || fail "server wrote no final mesh"
s_head=$(head -1 "$OUT/server.obj"); echo "server:      $s_head"
topo=$(echo "$s_head" | sed -n 's/.* topology \([0-9]*\) .*/\1/p')
[ "${topo:-0}" -ge 1 ] || fail "final mesh is at topology ${topo:-?}: no topology change was published"
nv=$(grep -c '^v ' "$OUT/server.obj"); nv0=$(grep -c '^v ' "$SRC/assets/meshes/kidney.obj")
[ "$nv" -gt "$nv0" ] || fail "final mesh has $nv vertices, not more than the coarse $nv0: not refined at the end"
for v in early late; do
  [ -f "$OUT/viewer_$v.obj" ] || fail "$v viewer wrote no mesh"
  v_head=$(head -1 "$OUT/viewer_$v.obj"); echo "viewer $v: $v_head"
  [ "$s_head" = "$v_head" ] || fail "$v viewer is not at the server's last frame"
  diff -q <(grep '^f ' "$OUT/server.obj") <(grep '^f ' "$OUT/viewer_$v.obj") >/dev/null ||
    fail "$v viewer's triangles differ from the server's"
  # quant_step 1e-5 m: half a step plus float rounding.
  "$BUILD/tests/integration/obj_compare" "$OUT/server.obj" "$OUT/viewer_$v.obj" 5.2e-6 ||
    fail "$v viewer's mesh differs from the server's"
done

if [ $have_rec = 1 ]; then
  "$BUILD/tests/integration/rec_topology" "$OUT/session.db" >"$OUT/topology.txt" || fail "rec_topology failed"
  grep -v '^MESHSTATE' "$OUT/topology.txt" || true
  versions=$(sed -n 's/^MESHSTATE organ=0 topology=\([0-9]*\) .*/\1/p' "$OUT/topology.txt" | sort -n | uniq)
  echo "recorded MeshState topology versions: $(echo $versions)"
  [ "$(echo "$versions" | wc -l)" -gt 1 ] || fail "the recording holds MeshState of one topology version only"
  max=$(echo "$versions" | tail -1)
  for t in $(seq 0 "$max"); do
    echo "$versions" | grep -qx "$t" || fail "no MeshState keyframe of topology version $t in the recording"
  done
  # Each topology event names the vertex count of that version's keyframe.
  last_ev=$(grep '^TOPOLOGY_EVENT organ=0 ' "$OUT/topology.txt" | tail -1) || fail "no EVENT_TOPOLOGY_CHANGED recorded"
  ev_nv=$(echo "$last_ev" | sed -n 's/.* value=\([0-9]*\) .*/\1/p')
  [ "$ev_nv" = "$nv" ] || fail "last topology event says $ev_nv vertices, the final mesh has $nv"
fi
echo "PASS"
