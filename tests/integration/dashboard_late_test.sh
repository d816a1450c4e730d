#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The instructor's dashboard started late (README "Classroom and remote
# sessions": a dashboard opened after the lab began). SessionEvent is
# transient-local, so a dashboard that joins takes the seat's past threshold
# crossings; they count in its crossings, but a crossing long over in the
# seat's simulated time must not put the seat in alert: before the fix every
# seat showed "above MPF" (red, 0.00 N) for the first 3 s of a dashboard
# started after its trainee had pressed.
# One seat: a scripted trainee palpates once (crossing ST and MPF) and exits;
# 3 s later (the crossings are then over 3 s old) a dashboard writes rows every
# 250 ms for 3 s. Asserts: it sees the scene, counts the past MPF crossing,
# and every row with the scene says "ok" at 0 N. Part 2 (below): the
# thresholds an instructor set reach a dashboard started after the change;
# part 3: a seat the instructor paused shows as paused until resumed, or
# (part 4) until its server restarts.
# usage: dashboard_late_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
TRAJ="$SRC/assets/trajectories/palpate_kidney.traj"
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition lab/seat01 \
  > "$OUT/server.log" 2>&1 & SRV=$!; PIDS+=("$SRV")
"$BUILD/client/haptic/viscera-haptic" --partition lab/seat01 --trajectory "$TRAJ" --start-on-answer --wait-server 60 \
  --quiet > "$OUT/haptic.log" 2>&1 || fail "the trainee did not exit cleanly"
grep -q "MPF crossed up" "$OUT/server.log" || fail "the trainee's press did not cross MPF"
# The press crossed up 2-3 s before the path's end; this margin puts it well
# past the hold in simulated time too (a margin, nothing is timed).
sleep 3
"$BUILD/client/dashboard/viscera-dashboard" --seats 1 --out "$OUT/dash" --interval-ms 250 --duration 3 \
  > "$OUT/dashboard.log" 2>&1 || fail "the dashboard failed"
csv="$OUT/dash/dashboard.csv"
# columns: 4 have_scene, 5 force_n, 7 alert, 9 crossings_mpf
rows=$(awk -F, '$3 == "lab/seat01" && $4 == 1' "$csv")
[ -n "$rows" ] || fail "the late dashboard never saw the seat's scene"
echo "$rows" | tail -2
echo "$rows" | awk -F, '$9 >= 1 { ok = 1 } END { exit !ok }' || fail "the late dashboard did not count the past MPF crossing"
bad=$(echo "$rows" | awk -F, '$7 != "ok" || $5 + 0 > 0' | head -3)
[ -z "$bad" ] || fail "a crossing long over put the seat in alert on a dashboard started late: $bad"

# Part 2: the thresholds in force. A trainee presses and holds (about
# 0.97 N); the instructor lowers SFT to 0.9 N below the held force
# (viscera-control thresholds); a dashboard started after the SFT crossing's
# hold judges the held force by the new levels: "SFT". Before the fix the
# server's SceneInfo kept the scene file's levels (SFT 1.5 N), so the
# dashboard said "MPF" and drew the old lines.
n_sft=$(grep -c "SFT crossed up" "$OUT/server.log" || true)
"$BUILD/client/haptic/viscera-haptic" --partition lab/seat01 --trajectory "$SRC/assets/trajectories/push_hold_kidney.traj" \
  --start-on-answer --duration 30 --quiet > "$OUT/hold.log" 2>&1 & H=$!; PIDS+=("$H")
n_mpf=$(grep -c "MPF crossed up" "$OUT/server.log" || true)
for ((t = 0; t < 600; t++)); do
  [ "$(grep -c "MPF crossed up" "$OUT/server.log" || true)" -gt "$n_mpf" ] && break
  sleep 0.1
done
[ "$(grep -c "MPF crossed up" "$OUT/server.log" || true)" -gt "$n_mpf" ] || fail "the held press never crossed MPF"
"$BUILD/client/control/viscera-control" --partition lab/seat01 thresholds 0 0.4 0.7 0.9 > "$OUT/control.log" 2>&1 ||
  fail "the thresholds were not applied"
for ((t = 0; t < 600; t++)); do
  [ "$(grep -c "SFT crossed up" "$OUT/server.log" || true)" -gt "$n_sft" ] && break
  sleep 0.1
done
[ "$(grep -c "SFT crossed up" "$OUT/server.log" || true)" -gt "$n_sft" ] || fail "the server did not take the new SFT"
sleep 4 # past the crossing's 3 s hold: the dashboard judges the force by the levels it was given
"$BUILD/client/dashboard/viscera-dashboard" --seats 1 --out "$OUT/dash2" --interval-ms 250 --duration 2 \
  > "$OUT/dashboard2.log" 2>&1 || fail "the second dashboard failed"
held=$(awk -F, '$3 == "lab/seat01" && $4 == 1 && $5 + 0 > 0.92' "$OUT/dash2/dashboard.csv")
[ -n "$held" ] || fail "the second dashboard saw no held press above 0.92 N"
echo "$held" | tail -1
bad=$(echo "$held" | awk -F, '$7 != "SFT"' | head -3)
[ -z "$bad" ] || fail "a force above the instructor's new SFT (0.9 N) not shown as SFT: $bad"

# Part 3: a paused seat. The instructor pauses it (as the README's
# five-minute block does); a dashboard started after that shows it paused
# (CSV column 14, and "paused" in light blue on the tile) until a resume.
# Before, nothing on the dashboard told a paused seat from an idle one.
"$BUILD/client/control/viscera-control" --partition lab/seat01 pause >> "$OUT/control.log" 2>&1 || fail "pause refused"
"$BUILD/client/dashboard/viscera-dashboard" --seats 1 --out "$OUT/dash3" --interval-ms 250 --duration 2 \
  > "$OUT/dashboard3.log" 2>&1 || fail "the third dashboard failed"
last=$(awk -F, '$3 == "lab/seat01" && $4 == 1' "$OUT/dash3/dashboard.csv" | tail -1)
[ -n "$last" ] || fail "the third dashboard never saw the scene"
[ "$(echo "$last" | cut -d, -f14)" = 1 ] || fail "a dashboard started after the pause does not show the seat paused: $last"
png=$(printf '%s/dash3/dashboard_%05d.png' "$OUT" "$(echo "$last" | cut -d, -f1)")
n=$("$BUILD/tests/integration/png_region" "$png" 6 28 130 40 115 179 255 30 | sed -n 's/^match=\([0-9]*\) of .*/\1/p')
echo "paused label pixels: ${n:-0}"
[ "${n:-0}" -ge 30 ] || fail "the tile does not say 'paused' (${n:-0} light blue pixels in its label)"
"$BUILD/client/control/viscera-control" --partition lab/seat01 resume >> "$OUT/control.log" 2>&1 || fail "resume refused"
"$BUILD/client/dashboard/viscera-dashboard" --seats 1 --out "$OUT/dash4" --interval-ms 250 --duration 2 \
  > "$OUT/dashboard4.log" 2>&1 || fail "the fourth dashboard failed"
last=$(awk -F, '$3 == "lab/seat01" && $4 == 1' "$OUT/dash4/dashboard.csv" | tail -1)
[ "$(echo "$last" | cut -d, -f14)" = 0 ] || fail "the seat still shown paused after the resume: $last"
kill -INT $H; wait $H || fail "the holding trainee failed"

# Part 4: a paused seat whose server restarts (a new server starts unpaused,
# and its history has no resume): a dashboard running across the restart
# shows the pause, then not once the new server is there.
"$BUILD/client/control/viscera-control" --partition lab/seat01 pause >> "$OUT/control.log" 2>&1 || fail "pause refused"
"$BUILD/client/dashboard/viscera-dashboard" --seats 1 --out "$OUT/dash5" --interval-ms 250 \
  > "$OUT/dashboard5.log" 2>&1 & D=$!; PIDS+=("$D")
csv5="$OUT/dash5/dashboard.csv"
paused_rows() { awk -F, -v v="$1" '$3 == "lab/seat01" && $4 == 1 && $14 == v' "$csv5" 2>/dev/null | wc -l; }
for ((t = 0; t < 600; t++)); do [ "$(paused_rows 1)" -gt 0 ] && break; sleep 0.1; done
[ "$(paused_rows 1)" -gt 0 ] || fail "the running dashboard never showed the pause"
kill -INT $SRV; wait $SRV || fail "server exited with an error"
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition lab/seat01 \
  > "$OUT/server2.log" 2>&1 & SRV=$!; PIDS+=("$SRV")
for ((t = 0; t < 600; t++)); do [ "$(paused_rows 0)" -gt 0 ] && break; sleep 0.1; done
[ "$(paused_rows 0)" -gt 0 ] || fail "the seat still shown paused after its server restarted: $(tail -1 "$csv5")"
kill -INT $D; wait $D || fail "the fifth dashboard failed"
kill -INT $SRV; wait $SRV || fail "the second server exited with an error"
PIDS=()
echo PASS
