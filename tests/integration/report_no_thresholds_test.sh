#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-report on a session whose tools have no palpation thresholds
# (assets/scenes/two_tools.yaml, as most scenes): an unset level must not read
# as a limit of 0 N. The HTML names each tool's thresholds as "no thresholds
# set" (never "ST 0.00 N"), and report.csv leaves ST_N, MPF_N and SFT_N empty
# like every other measure it cannot give; the measures above a level are n/a.
# Also: two recordings given one name are refused.
# usage: report_no_thresholds_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
fail() { echo "FAIL: $*" >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
VIEWER_ARGS="--interval-ms 1000" bash "$SRC/deploy/session.sh" "$BUILD" "$OUT/s" \
  "$SRC/assets/scenes/two_tools.yaml" "$SRC/assets/trajectories/palpate_kidney.traj" || fail "session did not run"
grep -q '^PALPATION tool=probe-left .*ST=0.000' "$OUT/s/server.out" || fail "the server saw thresholds on probe-left"
"$BUILD/client/report/viscera-report" --quiet --out "$OUT/report" --label "trainee=$OUT/s/session.db" ||
  fail "viscera-report failed"
HTML="$OUT/report/report.html"; CSV="$OUT/report/report.csv"
# the session pressed: the report has a force to show
peak=$(awk -F, 'NR==1 { for (i = 1; i <= NF; i++) if ($i == "peak_force_N") c = i } NR==2 { print $c }' "$CSV")
awk -v p="$peak" 'BEGIN { exit !(p > 0.3) }' || fail "peak force '$peak' N: the probe did not press"
grep -o 'tool probe-left</td><td>[^<]*' "$HTML"
grep -q 'tool probe-left</td><td>[^<]*no thresholds set' "$HTML" || fail "HTML: probe-left's thresholds not named as unset"
grep -q 'tool probe-right</td><td>[^<]*no thresholds set' "$HTML" || fail "HTML: probe-right's thresholds not named as unset"
! grep -q -E '(ST|MPF|SFT) 0\.00 N' "$HTML" || fail "HTML: an unset threshold shown as 0.00 N"
levels=$(awk -F, 'NR==1 { for (i = 1; i <= NF; i++) if ($i == "ST_N") c = i } NR==2 { print $c "," $(c + 1) "," $(c + 2) }' "$CSV")
[ "$levels" = ",," ] || fail "report.csv: ST_N,MPF_N,SFT_N = '$levels', want empty (not set)"
# Two recordings under one name would read as one trainee: refused (exit 2),
# naming both files. Before, the report drew two sections of that name.
rc=0; "$BUILD/client/report/viscera-report" --quiet --out "$OUT/twice" --label "a=$OUT/s/session.db" \
  --label "a=$OUT/s/session.db" 2>"$OUT/twice.err" || rc=$?
[ "$rc" = 2 ] || fail "two recordings named 'a': exit $rc, want 2"
grep -q "two recordings are named 'a'" "$OUT/twice.err" || fail "no word of the name given twice: $(cat "$OUT/twice.err")"
echo "report_no_thresholds: PASS (peak $peak N)"
