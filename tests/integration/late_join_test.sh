#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# A viewer started late, while the probe holds the organ dented, shows the
# current deformed mesh: its reconstruction (keyframe + latest delta) at the
# server's last published frame equals the server's exact positions within
# half a quantization step. Every step waits for an event (the server's
# threshold line, the viewer's keyframe, the viewer's frame showing the
# server's last frame; 60 s at most, a safety stop), never a wall-clock
# time (issue 15.6). usage: late_join_test.sh BUILD SRC OUT
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
await() { for _ in $(seq 600); do grep -q -- "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done; return 1; }
await "$OUT/server.log" "ST crossed up" || fail "the probe never pressed the organ"   # now holding it dented
rm -rf "$OUT/frames"
"$BUILD/client/viewer/viscera-viewer" "${common[@]}" --out "$OUT/frames" --interval-ms 0 \
  --dump-mesh "$OUT/viewer.obj" >"$OUT/viewer.out" 2>"$OUT/viewer.log" & VIEWER=$!; pids+=($VIEWER)
await "$OUT/viewer.out" "camera fixed" || fail "the late viewer got no keyframe"
kill -INT $SERVER; wait $SERVER || fail "server exited with an error"
# The viewer has applied the server's last frame: a frame written on SIGUSR1
# (interval 0) names it.
last=$(head -1 "$OUT/server.obj" | sed -n 's/.* frame \([0-9]*\)$/\1/p')
for _ in $(seq 300); do
  kill -USR1 $VIEWER
  sleep 0.2
  [ "$(tail -n 1 "$OUT/frames/frames.csv" 2>/dev/null | cut -d, -f5)" = "${last:-x}" ] && break
done
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
