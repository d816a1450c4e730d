#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Organ sleeping over DDS (issue 7, load): a classroom seat
# (assets/scenes/classroom_kidney.yaml, sleep_speed 1e-4 m/s) with a scripted
# trainee who waits 2 s away from the kidney, presses it 8 mm, and leaves.
# The server must put the kidney to sleep while the probe is away (before
# and after the press), wake it before the probe arrives so the trainee
# feels the press (peak above the 0.5 N ST threshold, the ST crossing
# logged), and report the sleeping steps in its summary (and its step CPU
# split into the tissue step and the rest). The scene's
# publish_keepalive (1 s): most MeshDelta frames of the still kidney are
# skipped, and a viewer joining after the kidney fell asleep again still
# gets the current shape (the last delta written, transient-local): its
# mesh equals the server's final mesh within half a quantisation step.
set -euo pipefail
# shellcheck source=prelude.sh
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
SCENE="$SRC/assets/scenes/classroom_kidney.yaml"
TRAJ="$OUT/press.traj"
printf '%s\n' "0 0.012 0.004 0.07" "2.0 0.012 0.004 0.07" "3.0 0.012 0.004 0.027" "3.5 0.012 0.004 0.027" \
  "4.5 0.012 0.004 0.07" "7 0.012 0.004 0.07" > "$TRAJ"
# Every step waits for the one before (the trainee starts its trajectory when
# it has the scene and exits at its end; 60 s at most each, a safety stop),
# never for a wall-clock time (issue 15.6).
"$BUILD/server/viscera-server" --scene "$SCENE" --partition sleep/seat --final-mesh "$OUT/final.obj" \
  > "$OUT/server.out" 2> "$OUT/server.log" &
srv=$!; PIDS+=("$srv")
"$BUILD/client/haptic/viscera-haptic" --partition sleep/seat --trajectory "$TRAJ" --wait-server 60 --quiet \
  > "$OUT/haptic.log" 2>&1 || fail "haptic client failed"
# The press ended (probe away) at 4.5 s of the trajectory, the client left
# after 7.5 s: the kidney settled and slept within about 0.2 s of it. The
# late viewer joins now and sees no new delta.
"$BUILD/client/viewer/viscera-viewer" --partition sleep/seat --out "$OUT/late" --interval-ms 100 --max-frames 3 \
  --duration 60 --dump-mesh "$OUT/late.obj" --quiet > "$OUT/viewer.out" 2> "$OUT/viewer.log" || fail "late viewer failed"
kill -INT "$srv"; wait "$srv" || fail "server exited with an error"
line=$(grep '^server: organs slept' "$OUT/server.log") || fail "no sleep summary in the server log"
echo "$line"
read -r sleeps wakes asleep steps < <(sed -n 's/^server: organs slept \([0-9]*\) times, woke \([0-9]*\) times; every organ asleep in \([0-9]*\) of \([0-9]*\) steps.*/\1 \2 \3 \4/p' "$OUT/server.log")
# Asleep before the press and again after it; woken once, by the probe.
[ "$sleeps" -ge 2 ] || fail "the kidney slept $sleeps times (expected at least 2: before and after the press)"
[ "$wakes" -ge 1 ] || fail "the kidney never woke"
# Away for about 5 of 7.5 s of the trajectory, and before it and after it:
# well over a third of the steps asleep.
awk -v a="$asleep" -v s="$steps" 'BEGIN { exit !(s > 0 && a / s > 0.35) }' ||
  fail "every organ asleep in only $asleep of $steps steps"
# The step's CPU split (tissue step, the rest): both parts measured, the
# pressed steps' tissue work visible at the p99, neither above the whole.
split=$(grep '^server: step CPU split' "$OUT/server.log") || fail "no step CPU split in the server log"
echo "$split"
read -r tmed tp99 rmed < <(sed -n 's/^server: step CPU split: tissue (contact and organs) median \([0-9.]*\) us p99 \([0-9.]*\) us; the rest ([^)]*) median \([0-9.]*\) us.*/\1 \2 \3/p' "$OUT/server.log")
cmed=$(sed -n 's/^server: step CPU time median \([0-9.]*\) us.*/\1/p' "$OUT/server.log")
awk -v t="${tmed:-x}" -v tp="${tp99:-x}" -v r="${rmed:-x}" -v c="${cmed:-x}" \
  'BEGIN { exit !(tp + 0 > 0 && r + 0 > 0 && t + 0 <= c + 0 && r + 0 <= c + 0) }' ||
  fail "step CPU split not plausible: tissue median ${tmed:-?} p99 ${tp99:-?}, rest ${rmed:-?}, whole ${cmed:-?} us"
peak=$(sed -n 's/^SUMMARY .*peak_force=\([0-9.]*\).*/\1/p' "$OUT/haptic.log")
echo "trainee's peak force ${peak:-none} N"
awk -v p="${peak:-0}" 'BEGIN { exit !(p > 0.5) }' || fail "the trainee felt ${peak:-no} N: the kidney did not wake for the press"
grep -q "ST crossed up" "$OUT/server.log" || fail "the server logged no ST crossing for the press"
read -r written skipped < <(sed -n 's/^server: \([0-9]*\) MeshDelta frames written, \([0-9]*\) skipped.*/\1 \2/p' "$OUT/server.log")
echo "MeshDelta: ${written:-?} written, ${skipped:-?} skipped"
[ -n "${skipped:-}" ] && [ "$skipped" -gt "$written" ] || fail "the still kidney's deltas were not skipped (${written:-?} written, ${skipped:-0} skipped)"
head -1 "$OUT/late.obj" | grep -q 'frame [0-9]' || fail "the late viewer applied no delta: $(head -1 "$OUT/late.obj")"
# Same vertex count and every coordinate within quant_step/2 (+ float rounding).
diff=$(awk '/^v / { if (FNR == NR) { a[++n] = $2 " " $3 " " $4 } else { split(a[++m], p, " ");
         for (k = 1; k <= 3; k++) { d = p[k] - $(k + 1); if (d < 0) d = -d; if (d > w) w = d } } }
       END { if (n != m || n == 0) print "count " n " vs " m; else printf "%.3g\n", w }' "$OUT/final.obj" "$OUT/late.obj")
echo "late viewer's mesh vs the server's final mesh: max difference $diff m"
awk -v d="$diff" 'BEGIN { exit !(d + 0 == d && d <= 5.1e-6) }' || fail "the late viewer's mesh differs from the server's: $diff"
echo "PASS: slept $sleeps times, woke $wakes, asleep in $asleep of $steps steps, press felt at $peak N; $skipped of $((written + skipped)) deltas skipped; late viewer within $diff m"
