#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-report per task (issue 16 item 3): a stone_removal session with two
# tasks running at once (find-spot by the probe, remove-stone by the
# extractor) is recorded and reported; the report's time of every task must
# equal the server's TASK line for it (same 3 decimals: the SessionEvents
# carry the task id and the server's operation time), every completed task
# of the server must be in the report and no other. Also: the HTML names the
# trainee (seat, station) and gives a verdict per limit, --limit changes
# the verdict, a bad --limit is a usage error (2).
# usage: report_tasks_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
REPORT="$BUILD/client/report/viscera-report"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log "$OUT"/*.err; do [ -f "$f" ] && { echo "--- $f"; tail -5 "$f"; }; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
. "$(dirname "$0")/tools_session.sh"
tools_session "$BUILD" "$OUT" "$SRC/assets/scenes/stone_removal.yaml" \
  "0:$SRC/assets/trajectories/palpate_kidney.traj" "1:$SRC/assets/trajectories/stone_removal_extractor.traj" \
  || fail "session did not run"
grep '^TASK ' "$OUT/server.out" || fail "server printed no TASK line"

"$REPORT" --out "$OUT/report" "$OUT/session.db" 2> "$OUT/report.err" || fail "viscera-report failed"
cat "$OUT/report.err"
CSV="$OUT/report/report.csv"; HTML="$OUT/report/report.html"
# tasks column: name=seconds;name=seconds
tasks=$(awk -F'"' 'NR == 2 { for (i = 2; i <= NF; i += 2) if ($i ~ /=/ && $i !~ / /) print $i }' "$CSV")
echo "report tasks: $tasks"
want=$(sed -n 's/^TASK task=\([^ ]*\) .*state=completed operation_time=\([0-9.]*\)$/\1=\2/p' "$OUT/server.out" | sort)
got=$(echo "$tasks" | tr ';' '\n' | sort)
[ -n "$want" ] || fail "the server completed no task"
[ "$(echo "$want" | wc -l)" -ge 2 ] || fail "the session should complete both tasks: $want"
[ "$got" = "$want" ] || fail "report tasks '$got' differ from the server's TASK lines '$want'"
echo "ok: every task equals the server's TASK line"

grep -q 'class=who><b>Trainee:</b> seat test/' "$HTML" || fail "the HTML does not name the trainee's seat"
grep -q 'station anonymous' "$HTML" || fail "the HTML does not name the station"
grep -q '<h3>Verdict <span class="verdict' "$HTML" || fail "no verdict in the HTML"
grep -q '@media print' "$HTML" || fail "no print layout"
for t in find-spot remove-stone; do grep -q "operation time, task $t (#" "$HTML" || fail "HTML lacks task $t"; done
# A limit every session passes and one it fails: the verdict follows.
"$REPORT" -q --out "$OUT/pass" --limits /dev/null --limit 'peak_force_N <= 100' "$OUT/session.db" 2>/dev/null \
  || fail "report with --limit failed"
grep -q ',PASS,' "$OUT/pass/report.csv" || fail "peak_force_N <= 100 should pass"
"$REPORT" -q --out "$OUT/fail" --limits /dev/null --limit 'peak_force_N <= 0.1*ST' "$OUT/session.db" 2>/dev/null \
  || fail "report with --limit failed"
grep -q ',FAIL,"peak_force_N <= 0.1\*ST"' "$OUT/fail/report.csv" || fail "peak_force_N <= 0.1*ST should fail"
st=0; "$REPORT" -q --out "$OUT/bad" --limit 'peak <= 1' "$OUT/session.db" 2>"$OUT/bad.err" || st=$?
[ $st = 2 ] && grep -q "unknown measure 'peak'" "$OUT/bad.err" || fail "a bad --limit should be a usage error naming it"
echo "PASS"
