#!/usr/bin/env bash
# A viewer started late, while the probe holds the organ dented, shows the
# current deformed mesh: its reconstruction (keyframe + latest delta) at the
# server's last published frame equals the server's exact positions within
# half a quantization step. usage: late_join_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-12}"
common=(--domain "$DOMAIN" --partition test/late)
mkdir -p "$OUT"; rm -f "$OUT"/*.obj
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done' EXIT
fail() { echo "FAIL: $*" >&2; tail -5 "$OUT"/*.log >&2; exit 1; }

"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" "${common[@]}" \
  --final-mesh "$OUT/server.obj" >"$OUT/server.out" 2>"$OUT/server.log" & SERVER=$!; pids+=($SERVER)
"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/push_hold_kidney.traj" "${common[@]}" \
  >"$OUT/haptic.out" 2>"$OUT/haptic.log" & HAPTIC=$!; pids+=($HAPTIC)
sleep 3.5   # the probe is now holding the organ dented
"$BUILD/client/viewer/viscera-viewer" "${common[@]}" --out "$OUT/frames" --interval-ms 0 \
  --dump-mesh "$OUT/viewer.obj" >"$OUT/viewer.out" 2>"$OUT/viewer.log" & VIEWER=$!; pids+=($VIEWER)
sleep 1.5
kill -INT $SERVER; wait $SERVER || fail "server exited with an error"
sleep 0.5
kill -INT $VIEWER; wait $VIEWER || fail "viewer exited with an error"
kill -INT $HAPTIC 2>/dev/null || true; wait $HAPTIC 2>/dev/null || true
pids=()
[ -f "$OUT/server.obj" ] || fail "server wrote no final mesh"
[ -f "$OUT/viewer.obj" ] || fail "late viewer wrote no mesh"
# Both files name the frame they hold; they must be the same frame.
s_head=$(head -1 "$OUT/server.obj"); v_head=$(head -1 "$OUT/viewer.obj")
echo "server: $s_head"; echo "viewer: $v_head"
[ "$s_head" = "$v_head" ] || fail "viewer is not at the server's last frame"
# The organ must really be deformed, or this test proves nothing.
"$BUILD/tests/integration/obj_compare" "$OUT/server.obj" "$SRC/assets/meshes/kidney.obj" 1e-3 && fail "organ was not deformed"
# quant_step 1e-5 m: half a step plus float rounding.
"$BUILD/tests/integration/obj_compare" "$OUT/server.obj" "$OUT/viewer.obj" 5.2e-6 || fail "late viewer mesh differs from the server's"
echo "PASS"
