#!/usr/bin/env bash
# The instructor's dashboard over a 3-seat lab (issue 7): seats 1 and 2 run a
# server, only seat 1 has a trainee (scripted palpation crossing ST and MPF),
# seat 3 has no server. Asserts from dashboard.csv: seat 1 raised an MPF
# alert and counted its crossings, seat 2 never alerted, seat 3 shows no
# scene; PNG grids were written.
# usage: dashboard_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
for s in seat01 seat02; do
  "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition lab/$s --duration 12 \
    > "$OUT/server_$s.log" 2>&1 & PIDS+=($!)
done
"$BUILD/client/dashboard/viscera-dashboard" --prefix lab --seats 3 --out "$OUT/dash" --interval-ms 500 --duration 11 \
  > "$OUT/dashboard.log" 2>&1 & DASH=$!; PIDS+=($DASH)
sleep 2
"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/palpate_kidney.traj" --partition lab/seat01 \
  --quiet > "$OUT/haptic.log" 2>&1 || fail "haptic client failed"
wait $DASH || fail "dashboard failed"
PIDS=()
csv="$OUT/dash/dashboard.csv"
[ -f "$csv" ] || fail "no dashboard.csv"
awk -F, 'NR>1 { seen[$3]=1; if ($4==1) scene[$3]=1; if ($7=="MPF") mpf[$3]++; if ($7!="ok") alert[$3]++;
                if ($9>m[$3]) m[$3]=$9; if ($6>p[$3]) p[$3]=$6 }
  END { printf "seat01: scene %d, frames with MPF alert %d, MPF crossings %d, peak %.2f N\n", scene["lab/seat01"], mpf["lab/seat01"], m["lab/seat01"], p["lab/seat01"];
        printf "seat02: scene %d, alert frames %d; seat03: scene %d\n", scene["lab/seat02"], alert["lab/seat02"], scene["lab/seat03"];
        exit !(scene["lab/seat01"] && mpf["lab/seat01"] >= 1 && m["lab/seat01"] >= 1 && p["lab/seat01"] > 0.5 &&
               scene["lab/seat02"] && alert["lab/seat02"] == 0 && seen["lab/seat03"] && !scene["lab/seat03"]) }' "$csv" \
  || fail "dashboard did not show the right seats, alerts and empty seat"
n=$(ls "$OUT/dash"/dashboard_*.png | wc -l)
echo "dashboard frames: $n"
[ "$n" -ge 10 ] || fail "too few dashboard frames ($n)"
echo PASS
