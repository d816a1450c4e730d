#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# A cut organ survives a server crash (issue 7 "after a restart the scene
# resumes from its last checkpoint", checkpoint format 2): real processes on
# loopback, for the xpbd spleen (cut_spleen_xpbd.yaml, cut_spleen.traj) and
# the mass-spring sheet (cut_block_mass_spring.yaml, cut_block.traj). The
# server runs with --checkpoint, a scripted scalpel draws the incision, the
# server is killed with SIGKILL after the cut, and a restarted server
# resumes from the checkpoint: the first MeshState keyframe it publishes has
# the topology of the last one before the kill (same vertex and triangle
# counts, other than the uncut mesh's), its log says it resumed, and it
# runs on (2 s) and exits cleanly. Two recordings per case, one per server
# life. usage: checkpoint_cut_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
wait_for() { for _ in $(seq 1 "${3:-300}"); do grep -q "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done; return 1; }
BASE="$OUT"
run_case() { # scene trajectory mesh
  local scene=$1 traj=$2 mesh=$3
  OUT="$BASE/$scene"; mkdir -p "$OUT"
  COMMON=(--domain "${VISCERA_DOMAIN:?}" --partition "test/checkpoint_cut/$scene")
  CK="$OUT/organ.ckpt"
  SCENE="$SRC/assets/scenes/$scene.yaml"

  "$BUILD/client/recorder/viscera-recorder" "${COMMON[@]}" --out "$OUT/before.db" --quiet \
    > "$OUT/recorder1.out" 2> "$OUT/recorder1.log" & REC=$!; PIDS+=($REC)
  "$BUILD/server/viscera-server" --scene "$SCENE" "${COMMON[@]}" --checkpoint "$CK" --checkpoint-every 0.25 \
    > "$OUT/server1.out" 2> "$OUT/server1.log" & SRV=$!; PIDS+=($SRV)
  wait_for "$OUT/server1.log" "running on domain" || fail "$scene: server did not start"
  wait_for "$OUT/recorder1.log" "recording topic viscera_MeshState" || fail "$scene: recorder never saw MeshState"
  "$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/$traj" "${COMMON[@]}" \
    --quiet > "$OUT/haptic.out" 2> "$OUT/haptic.log" & HAP=$!; PIDS+=($HAP)
  # A loaded machine may run the cut slowly: up to 60 s.
  wait_for "$OUT/server1.log" "ends its cut of organ" 600 || fail "$scene: the server never reported the end of the cut"
  wait $HAP || fail "$scene: haptic client failed"
  sleep 1.5 # checkpoints every 0.25 s of simulated time: several after the cut
  kill -9 $SRV; wait $SRV 2>/dev/null || true
  sleep 0.5
  kill -INT $REC; wait $REC 2>/dev/null || true
  [ -s "$CK" ] || fail "$scene: no checkpoint was written"

  "$BUILD/client/recorder/viscera-recorder" "${COMMON[@]}" --out "$OUT/after.db" --quiet \
    > "$OUT/recorder2.out" 2> "$OUT/recorder2.log" & REC=$!; PIDS+=($REC)
  sleep 1 # the recorder listens before the new server writes
  "$BUILD/server/viscera-server" --scene "$SCENE" "${COMMON[@]}" --checkpoint "$CK" --duration 2 \
    > "$OUT/server2.out" 2> "$OUT/server2.log" || fail "$scene: the restarted server failed"
  sleep 0.5
  kill -INT $REC; wait $REC 2>/dev/null || true
  PIDS=()

  grep -E "resumed|topology [0-9]+:" "$OUT/server2.log" | head -3
  grep -q "resumed from checkpoint" "$OUT/server2.log" || fail "$scene: the restarted server did not resume from its checkpoint"
  grep -q "cannot\|starting from rest" "$OUT/server2.log" && fail "$scene: the checkpoint was refused"
  "$BUILD/tests/integration/rec_topology" "$OUT/before.db" > "$OUT/before.txt" || fail "$scene: rec_topology (before) failed"
  "$BUILD/tests/integration/rec_topology" "$OUT/after.db" > "$OUT/after.txt" || fail "$scene: rec_topology (after) failed"
  last=$(grep '^MESHSTATE organ=0 ' "$OUT/before.txt" | tail -1) || fail "$scene: no keyframe recorded before the kill"
  first=$(grep '^MESHSTATE organ=0 ' "$OUT/after.txt" | head -1) || fail "$scene: no keyframe recorded after the restart"
  echo "last keyframe before the kill:     $last"
  echo "first keyframe after the restart:  $first"
  counts() { echo "$1" | sed -n 's/.* \(vertices=[0-9]* triangles=[0-9]*\).*/\1/p'; }
  [ -n "$(counts "$last")" ] && [ "$(counts "$last")" = "$(counts "$first")" ] \
    || fail "$scene: the restarted server's topology differs from the one before the kill"
  nv=$(echo "$last" | sed -n 's/.* vertices=\([0-9]*\) .*/\1/p')
  nv0=$(grep -c '^v ' "$SRC/assets/meshes/$mesh")
  [ "$nv" -ne "$nv0" ] || fail "$scene: the keyframe before the kill has the uncut mesh's $nv0 vertices: no cut"
}

run_case cut_spleen_xpbd cut_spleen.traj spleen.obj
run_case cut_block_mass_spring cut_block.traj tissue_block.obj
echo PASS
