#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# A clean client exit shows as "left", a killed client as "lost" (issue 18).
# One seat, a dashboard writing its CSV every 250 ms: a scripted trainee runs
# its trajectory to the end and exits 0: the seat shows client_left 1 and
# client_lost 0 (and the server says "haptic client left"). A second trainee
# is killed with SIGKILL while pressing: the seat shows client_lost 1 and
# client_left 0 (lease expired; the server says "haptic client lost"). The
# grid tile shows each state in words (grey "trainee left", red "trainee
# lost") on the scene, not cut off.
# usage: client_left_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
# Every step waits (60 s at most, a safety stop) for the event it needs: the
# server's log lines and the dashboard's own rows, never a wall-clock time
# (issue 15.6).
TRAJ="$SRC/assets/trajectories/palpate_kidney.traj"
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition lab/seat01 \
  > "$OUT/server.log" 2>&1 & SRV=$!; PIDS+=("$SRV")
"$BUILD/client/dashboard/viscera-dashboard" --seats 1 --out "$OUT/dash" --interval-ms 250 \
  > "$OUT/dashboard.log" 2>&1 & DASH=$!; PIDS+=("$DASH")
csv="$OUT/dash/dashboard.csv"
# columns: 11 client_lost, 13 client_left
last_row() { grep ',lab/seat01,' "$csv" 2>/dev/null | tail -1; }
nrows() { grep -c ',lab/seat01,' "$csv" 2>/dev/null || true; }
count() { local n; n=$(grep -c -- "$1" "$OUT/server.log" 2>/dev/null) || true; echo "${n:-0}"; }
# until COMMAND succeeds; 60 s at most
until_ok() { for ((t = 0; t < 600; t++)); do "$@" && return 0; sleep 0.1; done; return 1; }
col_is() { [ "$(last_row | cut -d, -f"$1")" = "$2" ]; }
more_rows() { [ "$(nrows)" -ge "$1" ]; }
more_lines() { [ "$(count "$1")" -gt "$2" ]; }
# label_px ROW R G B: pixels of that colour where the tile writes the
# trainee's state (client/dashboard/dash_draw.c: under the 22 px header, at
# the scene's top left) in the grid PNG of the CSV row ROW (its frame number).
label_px() {
  local png; png=$(printf '%s/dash/dashboard_%05d.png' "$OUT" "$(echo "$1" | cut -d, -f1)")
  "$BUILD/tests/integration/png_region" "$png" 6 28 130 20 "$2" "$3" "$4" 30 | sed -n 's/^match=\([0-9]*\) of .*/\1/p'
}
"$BUILD/client/haptic/viscera-haptic" --partition lab/seat01 --trajectory "$TRAJ" --wait-server 60 --quiet \
  > "$OUT/haptic1.log" 2>&1 || fail "the first trainee did not exit cleanly"
until_ok col_is 13 1 || true
row="$(last_row)"; echo "after a clean exit: $row"
[ "$(echo "$row" | cut -d, -f13)" = 1 ] || fail "a clean exit is not shown as left"
# The server's CLIENT_LOST("left") event: its line, then two more dashboard rows.
until_ok more_lines "haptic client left" 0 || fail "the server did not see the client leave"
until_ok more_rows $(($(nrows) + 2)) || fail "the dashboard stopped writing"
row="$(last_row)"
[ "$(echo "$row" | cut -d, -f11),$(echo "$row" | cut -d, -f13)" = "0,1" ] || fail "a clean exit shown as lost: $row"
# ... and the tile says so where the instructor sees it, in grey (it was at
# the end of the header, cut off at the default tile size).
n=$(label_px "$row" 153 153 153); echo "grey 'trainee left' pixels: ${n:-0}"
[ "${n:-0}" -ge 30 ] || fail "the tile does not show 'trainee left' (grey pixels ${n:-0} in its label)"

n_st=$(count "ST crossed up")
"$BUILD/client/haptic/viscera-haptic" --partition lab/seat01 --trajectory "$TRAJ" --wait-server 60 --quiet > "$OUT/haptic2.log" 2>&1 &
H=$!; PIDS+=("$H")
until_ok col_is 13 0 || fail "a new trainee did not clear 'left'"
until_ok more_lines "ST crossed up" "$n_st" || fail "the second trainee never pressed"
n_lost=$(count "haptic client lost")
kill -KILL $H
until_ok col_is 11 1 || true
until_ok more_lines "haptic client lost" "$n_lost" || fail "the server did not report the loss"
until_ok more_rows $(($(nrows) + 2)) || fail "the dashboard stopped writing"
row="$(last_row)"; echo "after kill -9: $row"
[ "$(echo "$row" | cut -d, -f11),$(echo "$row" | cut -d, -f13)" = "1,0" ] || fail "a killed client is not shown as lost: $row"
n=$(label_px "$row" 242 89 77); echo "red 'trainee lost' pixels: ${n:-0}"
[ "${n:-0}" -ge 30 ] || fail "the tile does not show 'trainee lost' in red (pixels ${n:-0} in its label)"
kill -INT $DASH; wait $DASH || fail "dashboard failed"
kill -INT $SRV; wait $SRV || fail "server exited with an error"
PIDS=()
echo PASS
