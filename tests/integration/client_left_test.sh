#!/usr/bin/env bash
# A clean client exit shows as "left", a killed client as "lost" (issue 18).
# One seat, a dashboard writing its CSV every 250 ms: a scripted trainee runs
# its trajectory to the end and exits 0: the seat shows client_left 1 and
# client_lost 0 (and the server says "haptic client left"). A second trainee
# is killed with SIGKILL while pressing: the seat shows client_lost 1 and
# client_left 0 (lease expired; the server says "haptic client lost").
# usage: client_left_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
TRAJ="$SRC/assets/trajectories/palpate_kidney.traj"
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition lab/seat01 --duration 20 \
  > "$OUT/server.log" 2>&1 & PIDS+=("$!")
"$BUILD/client/dashboard/viscera-dashboard" --seats 1 --out "$OUT/dash" --interval-ms 250 --duration 19 \
  > "$OUT/dashboard.log" 2>&1 & DASH=$!; PIDS+=("$DASH")
sleep 2
"$BUILD/client/haptic/viscera-haptic" --partition lab/seat01 --trajectory "$TRAJ" --wait-server 10 --quiet \
  > "$OUT/haptic1.log" 2>&1 || fail "the first trainee did not exit cleanly"
csv="$OUT/dash/dashboard.csv"
# columns: 11 client_lost, 13 client_left
last_row() { grep ',lab/seat01,' "$csv" | tail -1; }
for ((t = 0; t < 50; t++)); do [ "$(last_row | cut -d, -f13)" = 1 ] && break; sleep 0.1; done
row="$(last_row)"; echo "after a clean exit: $row"
[ "$(echo "$row" | cut -d, -f13)" = 1 ] || fail "a clean exit is not shown as left"
sleep 1 # the server's CLIENT_LOST("left") event has arrived by now
row="$(last_row)"
[ "$(echo "$row" | cut -d, -f11),$(echo "$row" | cut -d, -f13)" = "0,1" ] || fail "a clean exit shown as lost: $row"
grep -q "haptic client left" "$OUT/server.log" || fail "the server did not see the client leave"

"$BUILD/client/haptic/viscera-haptic" --partition lab/seat01 --trajectory "$TRAJ" --quiet > "$OUT/haptic2.log" 2>&1 &
H=$!; PIDS+=("$H")
for ((t = 0; t < 100; t++)); do [ "$(last_row | cut -d, -f13)" = 0 ] && break; sleep 0.1; done
[ "$(last_row | cut -d, -f13)" = 0 ] || fail "a new trainee did not clear 'left'"
sleep 1
kill -KILL $H
for ((t = 0; t < 50; t++)); do [ "$(last_row | cut -d, -f11)" = 1 ] && break; sleep 0.1; done
sleep 1
row="$(last_row)"; echo "after kill -9: $row"
[ "$(echo "$row" | cut -d, -f11),$(echo "$row" | cut -d, -f13)" = "1,0" ] || fail "a killed client is not shown as lost: $row"
grep -q "haptic client lost" "$OUT/server.log" || fail "the server did not report the loss"
wait $DASH || fail "dashboard failed"
PIDS=()
echo PASS
