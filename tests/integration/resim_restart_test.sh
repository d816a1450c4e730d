#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# A server killed (-9) mid-session and restarted from its checkpoint while the
# recorder keeps running: the recording holds two runs of the server in one
# partition, each numbering its steps and AppliedInputs from its own start.
# viscera-resim re-simulates one run at a time, never the two mixed:
#   - by default the last run (resumed from its recorded checkpoint state):
#     RUN run=2 runs=2, RESUMED at the restarted server's step, bit exact;
#   - --run 1: the first run, from rest up to the kill, bit exact;
#   - --run 3: exit 2 naming the two runs.
# viscera-report on that recording agrees with the resumed server's own
# measures (its PALPATION line), which leave out what run 1 did after the
# checkpoint: before, that stretch of simulated time was counted twice and
# the force chart ran back in time; and it warns of the restart.
# Before, both runs' inputs were applied in one re-simulation: "diverged",
# 18446744073709549925 AppliedInputs "missing" (a negative count) and exit 1.
# Steps wait for the processes' own output (the recorder's topic line, the
# recorded AppliedInput count, the checkpoint file, the "resumed" line).
# usage: resim_restart_test.sh BUILD SRC OUT
set -uo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-169}"
rm -rf "$OUT"; mkdir -p "$OUT"
SCENE="$SRC/assets/scenes/default.yaml"; TRAJ="$SRC/assets/trajectories/palpate_kidney.traj"
SRV="$BUILD/server/viscera-server"; REC="$BUILD/client/recorder/viscera-recorder"
HAP="$BUILD/client/haptic/viscera-haptic"; RESIM="$BUILD/server/viscera-resim"
common=(--domain "$DOMAIN" --partition resim/restart)
CK="$OUT/session.ckpt"; DB="$OUT/session.db"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do echo "--- $f"; tail -6 "$f"; done >&2; exit 1; }
applied() { sqlite3 "$DB" "SELECT count(*) FROM samples WHERE topic_id = (SELECT id FROM topics WHERE name = 'viscera_AppliedInput')" 2>/dev/null || echo 0; }

"$SRV" --scene "$SCENE" "${common[@]}" --checkpoint "$CK" --checkpoint-every 0.5 >"$OUT/server1.out" 2>"$OUT/server1.log" &
S1=$!; PIDS+=("$S1")
"$REC" "${common[@]}" --out "$DB" >"$OUT/recorder.out" 2>"$OUT/recorder.log" & R=$!; PIDS+=("$R")
for _ in $(seq 1 300); do grep -q "recording topic viscera_AppliedInput" "$OUT/recorder.log" && break; sleep 0.1; done
grep -q "recording topic viscera_AppliedInput" "$OUT/recorder.log" || fail "the recorder never saw the server's AppliedInput"
"$HAP" --trajectory "$TRAJ" "${common[@]}" --start-on-answer --quiet >"$OUT/haptic.out" 2>"$OUT/haptic.log" & H=$!
PIDS+=("$H")
# Kill run 1 once it has applied 1.5 s of the path (the probe pressing) and checkpointed.
for _ in $(seq 1 600); do [ "$(applied)" -gt 1500 ] && [ -s "$CK" ] && break; sleep 0.05; done
[ "$(applied)" -gt 1500 ] && [ -s "$CK" ] || fail "run 1 recorded $(applied) AppliedInputs and no checkpoint"
kill -9 "$S1"; wait "$S1" 2>/dev/null
"$SRV" --scene "$SCENE" "${common[@]}" --checkpoint "$CK" --checkpoint-every 0.5 >"$OUT/server2.out" 2>"$OUT/server2.log" &
S2=$!; PIDS+=("$S2")
for _ in $(seq 1 300); do grep -q "resumed from checkpoint" "$OUT/server2.log" && break; sleep 0.1; done
step=$(sed -n 's/.*resumed from checkpoint .* (step \([0-9]*\)).*/\1/p' "$OUT/server2.log")
[ -n "$step" ] || fail "run 2 did not resume from the checkpoint"
wait "$H" || fail "the haptic client failed"
# Run 2 answered the hand: it applied inputs of its own.
kill -INT "$S2"; wait "$S2" || fail "run 2 failed"
kill -INT "$R"; wait "$R" || fail "the recorder failed"
writers=$(sqlite3 "$DB" "SELECT count(*) FROM writers WHERE topic_id = (SELECT id FROM topics WHERE name = 'viscera_SceneInfo')")
[ "$writers" = 2 ] || fail "the recording holds $writers SceneInfo writers, not the two runs"

"$RESIM" "$DB" --quiet >"$OUT/resim.out" 2>"$OUT/resim.log"; rc=$?
cat "$OUT/resim.out" "$OUT/resim.log"
grep -q '^RUN run=2 runs=2$' "$OUT/resim.out" || fail "default: not run 2 of 2"
grep -q "^RESUMED step=$step " "$OUT/resim.out" || fail "default: run 2 not started from its resume state (step $step)"
grep -q 'note: the server ran 2 times' "$OUT/resim.log" || fail "default: no note that the session holds two runs"
[ $rc -eq 0 ] && grep -q '^RESIM PASS .*bit_exact=1' "$OUT/resim.out" || fail "default: run 2 not bit exact (exit $rc)"
grep -q -E '^INPUTS .* lost=0$' "$OUT/resim.out" || fail "default: AppliedInputs counted as lost"

"$RESIM" "$DB" --run 1 --quiet >"$OUT/resim1.out" 2>"$OUT/resim1.log"; rc=$?
cat "$OUT/resim1.out"
grep -q '^RUN run=1 runs=2$' "$OUT/resim1.out" || fail "--run 1: not run 1 of 2"
grep -q '^RESUMED' "$OUT/resim1.out" && fail "--run 1: run 1 started from a resume state"
[ $rc -eq 0 ] && grep -q '^RESIM PASS .*bit_exact=1' "$OUT/resim1.out" || fail "--run 1: not bit exact (exit $rc)"

"$RESIM" "$DB" --run 3 --quiet >"$OUT/resim3.out" 2>"$OUT/resim3.log"; rc=$?
[ $rc -eq 2 ] && grep -q -- '--run 3: the session holds 2 run(s)' "$OUT/resim3.log" ||
  fail "--run 3: exit $rc, $(cat "$OUT/resim3.log")"
# viscera-report on the same recording: the resumed server's measures (restored
# from its checkpoint) leave out what run 1 did after the checkpoint; so does
# the report, instead of counting that stretch of simulated time twice.
"$BUILD/client/report/viscera-report" --quiet --out "$OUT/report" "$DB" 2>"$OUT/report.log" ||
  fail "viscera-report failed: $(cat "$OUT/report.log")"
cat "$OUT/report.log"
grep -q "the server restarted 1 time(s)" "$OUT/report.log" || fail "report: no warning of the restart"
line=$(grep '^PALPATION tool=probe ' "$OUT/server2.out") || fail "run 2 printed no PALPATION line"
val() { echo "$line" | grep -o " $1=[^ ]*" | cut -d= -f2; }
col() { awk -F, -v k="$1" 'NR==1 { for (i = 1; i <= NF; i++) if ($i == k) c = i } NR==2 { print $c }' "$OUT/report/report.csv"; }
# the report replays the recorded feedback: within 0.05 s or 3 % of the server's own figure
near() { awk -v a="$1" -v b="$2" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 0.05 || d <= 0.03 * b) }'; }
for m in "contact_time contact_time_s" "time_above_ST time_above_ST_s" "time_above_MPF time_above_MPF_s"; do
  set -- $m
  s=$(val "$1"); r=$(col "$2")
  echo "$1: server $s s, report $r s"
  near "${r:-0}" "${s:-0}" || fail "report $2 = $r s, the server's $1 = $s s"
done
echo "PASS: run 1 (from rest) and run 2 (resumed at step $step) each re-simulated bit for bit; the report agrees with run 2's measures"
