#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-report on a cutting session (assets/scenes/cut_block_mass_spring.yaml,
# cut_block.traj: the scalpel cuts the tissue block once): the report gives the
# cuts from the server's CUT_BEGIN / CUT_END events. report.csv's cuts,
# cut_topology_changes equal the server's own "ends its cut" lines, cut_time_s
# is positive; the HTML has a Cuts table whose row carries the server's words
# at the cut's end (incision width). Before, a cutting session's report said
# nothing of the cut (the scalpel feels no force: every measure n/a).
# usage: report_cuts_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
fail() { echo "FAIL: $*" >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
VIEWER_ARGS="--interval-ms 1000" bash "$SRC/deploy/session.sh" "$BUILD" "$OUT/s" \
  "$SRC/assets/scenes/cut_block_mass_spring.yaml" "$SRC/assets/trajectories/cut_block.traj" || fail "session did not run"
ends=$(grep -c "ends its cut of organ" "$OUT/s/server.log" || true)
changes=$(sed -n 's/.*ends its cut of organ .*: \([0-9]*\) topology change(s).*/\1/p' "$OUT/s/server.log" |
  awk '{ s += $1 } END { print s + 0 }')
width=$(sed -n 's/.*\(incision width [0-9.]* mm mean, [0-9.]* mm max\).*/\1/p' "$OUT/s/server.log" | head -n 1)
echo "server: $ends cut(s) ended, $changes topology change(s), '$width'"
[ "$ends" -ge 1 ] && [ "$changes" -ge 1 ] && [ -n "$width" ] || fail "the session did not cut (server.log)"
"$BUILD/client/report/viscera-report" --quiet --out "$OUT/report" "$OUT/s/session.db" || fail "viscera-report failed"
CSV="$OUT/report/report.csv"; HTML="$OUT/report/report.html"
col() { awk -F, -v k="$1" 'NR==1 { for (i = 1; i <= NF; i++) if ($i == k) c = i } NR==2 { print $c }' "$CSV"; }
echo "report.csv: cuts=$(col cuts) cut_time_s=$(col cut_time_s) cut_topology_changes=$(col cut_topology_changes)"
[ "$(col cuts)" = "$ends" ] || fail "report.csv cuts '$(col cuts)', the server ended $ends"
[ "$(col cut_topology_changes)" = "$changes" ] || fail "report.csv cut_topology_changes '$(col cut_topology_changes)', server $changes"
awk -v t="$(col cut_time_s)" 'BEGIN { exit !(t > 0) }' || fail "report.csv cut_time_s '$(col cut_time_s)' is not positive"
grep -q "<h3>Cuts</h3>" "$HTML" || fail "report.html has no Cuts section"
grep -q "<td>scalpel</td>.*$width" "$HTML" || fail "report.html: no cut row of the scalpel with the server's '$width'"
echo "report_cuts: PASS"
