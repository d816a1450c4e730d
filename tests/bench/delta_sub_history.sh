#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# delta_sub (the load benchmark's subscriber): a MeshDelta written before it
# joined, handed over from the writer's history at the join, is counted
# apart (history=N on its SUB line), not as a delivery latency: its age is
# how long the organ has been at rest, not how long the network took.
# A classroom kidney with a keepalive of 60 s: once it has settled and
# slept, its last delta stays the only one for a minute. A first subscriber
# waits until the server has written a keyframe and a delta; the second one
# then joins and must count that delta as history (exactly one: MeshDelta is
# keep-last 1) with no latency sample from it. Figures are not judged.
# usage: delta_sub_history.sh SRC BUILD OUT
set -euo pipefail
SRC="$1" BUILD="$2" OUT="$3"
rm -rf "$OUT"; mkdir -p "$OUT"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; tail -5 "$OUT"/*.out >&2 || true; exit 1; }
SUB="$BUILD/tests/bench/delta_sub"
sed -e 's/publish_keepalive: 1.0/publish_keepalive: 60/' -e "s#\.\./meshes/#$SRC/assets/meshes/#" \
  "$SRC/assets/scenes/classroom_kidney.yaml" > "$OUT/kidney_quiet.yaml"
grep -q "publish_keepalive: 60" "$OUT/kidney_quiet.yaml" || fail "the scene has no keepalive line to change"
"$BUILD/server/viscera-server" --scene "$OUT/kidney_quiet.yaml" --partition hist --duration 60 --quiet \
  > "$OUT/server.out" 2>&1 &
PIDS+=($!)
# Until the server has written a keyframe and a delta (each try 2 s; a
# delta_sub that saw no keyframe exits 3).
seen=0
for ((k = 0; k < 15; k++)); do
  "$SUB" --partition hist --duration 2 --name probe > "$OUT/probe.out" 2>&1 || true
  if grep -Eq '^SUB name=probe keyframes=[1-9][0-9]* .* deltas=[1-9]' "$OUT/probe.out"; then seen=1; break; fi
done
[ $seen = 1 ] || fail "no keyframe and delta from the server within 15 tries"
# The kidney settles and sleeps within its first second (sleep_after 0.1 s):
# from then on nothing new is written for 60 s.
sleep 2
"$SUB" --partition hist --duration 2 --name late > "$OUT/late.out" 2>&1 || fail "the late subscriber failed"
line=$(grep '^SUB name=late ' "$OUT/late.out") || fail "no SUB line from the late subscriber"
echo "$line"
case "$line" in *" keyframes=0 "*) fail "the late subscriber got no keyframe" ;; esac
case "$line" in *" deltas=1 "*) ;; *) fail "expected exactly the one delta of the writer's history" ;; esac
case "$line" in *" history=1") ;; *) fail "the delta from before the join was not counted as history" ;; esac
case "$line" in *" latency_us_median=0.0 latency_us_p99=0.0 latency_us_max=0.0 "*) ;;
  *) fail "the delta from before the join was taken as a latency sample" ;;
esac
echo PASS
