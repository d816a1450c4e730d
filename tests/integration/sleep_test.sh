#!/usr/bin/env bash
# Organ sleeping over DDS (issue 7, load): a classroom seat
# (assets/scenes/classroom_kidney.yaml, sleep_speed 1e-4 m/s) with a scripted
# trainee who waits 2 s away from the kidney, presses it 8 mm, and leaves.
# The server must put the kidney to sleep while the probe is away (before
# and after the press), wake it before the probe arrives so the trainee
# feels the press (peak above the 0.5 N ST threshold, the ST crossing
# logged), and report the sleeping steps in its summary.
set -euo pipefail
# shellcheck source=prelude.sh
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
SCENE="$SRC/assets/scenes/classroom_kidney.yaml"
TRAJ="$OUT/press.traj"
printf '%s\n' "0 0.012 0.004 0.07" "2.0 0.012 0.004 0.07" "3.0 0.012 0.004 0.027" "3.5 0.012 0.004 0.027" \
  "4.5 0.012 0.004 0.07" "7 0.012 0.004 0.07" > "$TRAJ"
"$BUILD/server/viscera-server" --scene "$SCENE" --partition sleep/seat --duration 8 \
  > "$OUT/server.out" 2> "$OUT/server.log" &
srv=$!; PIDS+=("$srv")
sleep 0.5
"$BUILD/client/haptic/viscera-haptic" --partition sleep/seat --trajectory "$TRAJ" --duration 6.5 --quiet \
  > "$OUT/haptic.log" 2>&1 || fail "haptic client failed"
wait "$srv" || fail "server exited with an error"
line=$(grep '^server: organs slept' "$OUT/server.log") || fail "no sleep summary in the server log"
echo "$line"
read -r sleeps wakes asleep steps < <(sed -n 's/^server: organs slept \([0-9]*\) times, woke \([0-9]*\) times; every organ asleep in \([0-9]*\) of \([0-9]*\) steps.*/\1 \2 \3 \4/p' "$OUT/server.log")
# Asleep before the press and again after it; woken once, by the probe.
[ "$sleeps" -ge 2 ] || fail "the kidney slept $sleeps times (expected at least 2: before and after the press)"
[ "$wakes" -ge 1 ] || fail "the kidney never woke"
# Away for about 5.5 of 8 s: well over a third of the steps asleep.
awk -v a="$asleep" -v s="$steps" 'BEGIN { exit !(s > 0 && a / s > 0.35) }' ||
  fail "every organ asleep in only $asleep of $steps steps"
peak=$(sed -n 's/^SUMMARY .*peak_force=\([0-9.]*\).*/\1/p' "$OUT/haptic.log")
echo "trainee's peak force ${peak:-none} N"
awk -v p="${peak:-0}" 'BEGIN { exit !(p > 0.5) }' || fail "the trainee felt ${peak:-no} N: the kidney did not wake for the press"
grep -q "ST crossed up" "$OUT/server.log" || fail "the server logged no ST crossing for the press"
echo "PASS: slept $sleeps times, woke $wakes, asleep in $asleep of $steps steps, press felt at $peak N"
