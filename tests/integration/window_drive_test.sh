#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Interactive driving without a haptic device (issue 4), under Xvfb: the
# window viewer (--window --drive 0) is fed a scripted input session through
# its SDL event queue (mouse motion down the screen, wheel and W into the
# kidney, space, then R to reset), publishes ToolCommand at 1 kHz, and the
# server reports contact. Also: the window shows exactly the rendered frame,
# and closing the viewer releases the tool (liveliness: the writer left).
# usage: window_drive_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-121}"
common=(--domain "$DOMAIN" --partition test/window)
mkdir -p "$OUT"; rm -rf "$OUT"/*
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done' EXIT
fail() { echo "FAIL: $*" >&2; tail -n 8 "$OUT"/*.log "$OUT"/*.out >&2 || true; exit 1; }

cat > "$OUT/session.input" <<'INPUT'
# t(s) since the first frame: down the screen onto the kidney's top, press in
0.3 motion 0 20
0.5 motion 0 20
0.7 motion 0 20
1.0 wheel 3
1.2 key_down space
1.5 key_down w
2.3 key_up w
2.6 key_up space
# back home, clear of the organ
3.2 key_down r
3.3 key_up r
INPUT
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" "${common[@]}" \
  >"$OUT/server.out" 2>"$OUT/server.log" & SERVER=$!; pids+=($SERVER)
xvfb-run -a -s "-screen 0 800x600x24 -nolisten tcp" \
  "$BUILD/client/viewer/viscera-viewer" "${common[@]}" --window --drive 0 --script-input "$OUT/session.input" \
  --out "$OUT/frames" --interval-ms 250 >"$OUT/viewer.out" 2>"$OUT/viewer.log" \
  || fail "window viewer failed"
sleep 0.5
kill -INT $SERVER; wait $SERVER || fail "server exited with an error"
pids=()

grep -q "SDL video driver x11" "$OUT/viewer.out" || fail "the window did not open on the X server"
grep -q " 0 of [0-9]* window pixels differ" "$OUT/viewer.out" || fail "the window does not show the rendered frame"
sent=$(grep -o '[0-9]* commands sent for tool 0' "$OUT/viewer.out" | cut -d' ' -f1)
[ "${sent:-0}" -gt 100 ] || fail "the 1 kHz thread sent ${sent:-no} commands"
# The 10 scripted events must all arrive; the X server may add its own (a
# pointer motion when the window maps), so more is fine.
events=$(grep -o '[0-9]* input events' "$OUT/viewer.out" | cut -d' ' -f1)
[ "${events:-0}" -ge 10 ] || fail "not every scripted event reached the mapping (${events:-no} input events)"
# The server: commands applied, contact made with the driven probe.
grep -q "ST crossed up: tool 'probe'" "$OUT/server.log" || fail "the driven probe never pressed the kidney"
peak=$(grep -o 'peak_force=[0-9.]*' "$OUT/server.out" | head -1 | cut -d= -f2)
awk -v p="$peak" 'BEGIN { exit !(p > 0.5) }' || fail "peak force $peak N"
# Closing the window removed the client, noticed through DDS (its writer
# deleted, or its liveliness lost when the exit outran the goodbye), not by
# the 0.5 s command timeout.
grep "tool 0: haptic client l" "$OUT/server.log" | tail -1 | grep -q "client left\|liveliness lost" \
  || fail "server did not release the tool through DDS when the viewer left: $(grep 'tool 0' "$OUT/server.log")"
# Frames (every 250 ms and one at exit, 1 s after R): contact while pressed,
# none at the end (home is above the organ).
awk -F, 'NR>1 { if ($6==1) c++; last=$6 } END { printf "frames in contact: %d, last frame in contact: %d\n", c, last;
  exit !(c>=1 && last==0) }' "$OUT/frames/frames.csv" || fail "frames do not show the press and the reset"
echo "$(grep 'window closed' "$OUT/viewer.out")"
echo PASS
