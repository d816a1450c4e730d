#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The instructor's dashboard over a 3-seat lab (issue 7): seats 1 and 2 run a
# server, only seat 1 has a trainee (scripted palpation crossing ST and MPF),
# seat 3 has no server. Asserts from dashboard.csv: seat 1 raised an MPF
# alert and counted its crossings, seat 2 never alerted, seat 3 shows no
# scene; PNG grids were written.
# usage: dashboard_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
# Every step waits (60 s at most, a safety stop) for the event it needs: the
# trainee starts when it has the scene and exits at its trajectory's end;
# the dashboard is stopped once it has written rows after that and at least
# 10 frames (its own counters), never after a wall-clock time (issue 15.6).
SRVS=()
for s in seat01 seat02; do
  "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition lab/$s \
    > "$OUT/server_$s.log" 2>&1 & PIDS+=($!); SRVS+=($!)
done
"$BUILD/client/dashboard/viscera-dashboard" --prefix lab --seats 3 --out "$OUT/dash" --interval-ms 500 \
  > "$OUT/dashboard.log" 2>&1 & DASH=$!; PIDS+=($DASH)
"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/palpate_kidney.traj" --partition lab/seat01 \
  --wait-server 60 --quiet > "$OUT/haptic.log" 2>&1 || fail "haptic client failed"
rows() { grep -c ',lab/seat03,' "$OUT/dash/dashboard.csv" 2>/dev/null || true; }
pngs() { ls "$OUT/dash"/dashboard_*.png 2>/dev/null | wc -l; }
r0=$(rows)
for _ in $(seq 600); do [ "$(rows)" -ge $((r0 + 2)) ] && [ "$(pngs)" -ge 10 ] && break; sleep 0.1; done
kill -INT $DASH; wait $DASH || fail "dashboard failed"
for p in "${SRVS[@]}"; do kill -INT "$p"; wait "$p" || fail "a server exited with an error"; done
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
