#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The instructor's dashboard live in a window (issue 7), under Xvfb: one seat
# whose scripted trainee presses above MPF and holds. viscera-dashboard
# --window is driven by a script of keys and clicks through its SDL event
# queue: key 1 focuses the seat, Esc returns to the grid, a click on the
# tile focuses it, a click returns, Tab focuses it again. Asserts: the
# window opened on the X server and every view change happened, in order;
# a focused frame (focus_NNNNN.png: what the window showed) has the red
# above-MPF badge and the force curve; grid frames were written all along
# (dashboard.csv flags which frames were focused); the window showed exactly
# the drawing (read back at exit); the process exited cleanly by itself.
# usage: dashboard_window_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
. "$(dirname "$0")/dashboard_lib.sh"
# Window 1024 x (680 + 22 footer); the 1-seat grid (320 x 332) is centred in
# the 680 px above the footer, so its tile's centre is at (512, 340).
W=1024; H=680

write_hold_traj "$OUT/hold.traj" 40
# t (s) since the window opened
cat > "$OUT/dash.input" <<'INPUT'
4.0 key_down 1
4.1 key_up 1
8.0 key_down escape
8.1 key_up escape
9.0 button_down 512 340
9.1 button_up 512 340
12.0 button_down 40 40
12.1 button_up 40 40
13.0 key_down tab
13.1 key_up tab
INPUT
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition lab/seat01 \
  > "$OUT/server.out" 2> "$OUT/server.log" & SERVER=$!; PIDS+=($SERVER)
xvfb-run -a -s "-screen 0 1280x1024x24 -nolisten tcp" \
  "$BUILD/client/dashboard/viscera-dashboard" --prefix lab --seats 1 --window --size ${W}x${H} \
  --script-input "$OUT/dash.input" --out "$OUT/dash" --interval-ms 500 \
  > "$OUT/dashboard.out" 2> "$OUT/dashboard.log" & DASHP=$!; PIDS+=($DASHP)
# The trainee starts once the window is up, so the press overlaps the focused periods.
for _ in $(seq 300); do grep -q "window open" "$OUT/dashboard.out" 2>/dev/null && break
  kill -0 $DASHP 2>/dev/null || break; sleep 0.2; done
grep -q "SDL video driver x11" "$OUT/dashboard.out" || fail "the dashboard window did not open on the X server"
"$BUILD/client/haptic/viscera-haptic" --trajectory "$OUT/hold.traj" --partition lab/seat01 --quiet \
  > "$OUT/haptic.log" 2>&1 & HAPTIC=$!; PIDS+=($HAPTIC)
wait $DASHP || fail "dashboard window exited with an error"
kill -9 $HAPTIC 2>/dev/null || true
kill -INT $SERVER; wait $SERVER || true
PIDS=()

views=$(grep -o 'dashboard: \(focus lab/seat01\|grid\) (.*)' "$OUT/dashboard.out" | tr '\n' ';')
echo "views: $views"
[ "$views" = "dashboard: focus lab/seat01 (key 1);dashboard: grid (escape);dashboard: focus lab/seat01 (click);dashboard: grid (click);dashboard: focus lab/seat01 (tab);" ] \
  || fail "the scripted keys and clicks did not change the view as expected"
grep -q " 0 of [0-9]* window pixels differ" "$OUT/dashboard.out" || fail "the window does not show the drawing"
csv="$OUT/dash/dashboard.csv"
awk -F, 'NR>1 { n++; if ($12==1) f++; if ($7=="MPF") a++ } END { printf "frames: %d, focused %d, with an MPF alert %d\n", n, f, a;
  exit !(n >= 10 && f >= 3 && n - f >= 3 && a >= 1) }' "$csv" || fail "grid frames, focused frames or alerts missing"
scan_focus_frames "$OUT/dash" $W $H
echo "focus frames: $(ls "$OUT/dash"/focus_*.png | wc -l), with the red MPF badge: $red (force curve in $curve, red alert frame in $framed)"
grep -q "MPF crossed up" "$OUT/server.log" || fail "the server never reported the press above MPF (starved?)"
[ "$red" -ge 1 ] && [ "$curve" -ge 1 ] && [ "$framed" -ge 1 ] \
  || fail "no focused frame shows the above-MPF badge with the force curve and the red frame"
grep 'window closed' "$OUT/dashboard.out"
echo PASS
