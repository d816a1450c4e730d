#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-report of a lab (issue 16 items 3 and 6): deploy/lab.sh runs 3
# seats (a server and a scripted trainee each, partitions lab/seat01..03)
# and records every lab partition into one file; the report must have one
# section per seat (3 rows in report.csv, 3 sections and a lab summary in
# the HTML), each naming its seat, and each seat's figures must match that
# seat's server PALPATION line (times within 0.05 s or 3 %, peak within
# 0.02 N, mean force within 3 %, crossings equal), not the sum of the lab.
# usage: report_lab_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
REPORT="$BUILD/client/report/viscera-report"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/lab/*.log "$OUT"/*.err; do [ -f "$f" ] && { echo "--- $f"; tail -5 "$f"; }; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
bash "$SRC/deploy/lab.sh" --build "$BUILD" --out "$OUT/lab" --seats 3 --trainees --viewers 0 --duration 9 \
  > "$OUT/lab.out" 2>&1 || { cat "$OUT/lab.out"; fail "lab.sh failed"; }
for s in 1 2 3; do grep -q '^PALPATION tool=probe ' "$OUT/lab/seat0$s-server.log" || fail "seat0$s: no PALPATION line"; done

"$REPORT" --out "$OUT/report" "$OUT/lab/lab.db" 2> "$OUT/report.err" || fail "viscera-report failed"
cat "$OUT/report.err"
CSV="$OUT/report/report.csv"; HTML="$OUT/report/report.html"
[ "$(tail -n +2 "$CSV" | wc -l)" -eq 3 ] || fail "report.csv should have 3 rows (one per seat)"
[ "$(grep -c '<h2 id=s[0-9]' "$HTML")" -eq 3 ] || fail "the HTML should have 3 seat sections"
grep -q '<h2 class=first id=summary>Lab summary</h2>' "$HTML" || fail "no lab summary table"

col() { awk -F, -v lab="\"lab $1\"" -v name="$2" 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  $1 == lab { v = $c[name]; gsub(/"/, "", v); print v }' "$CSV"; }
srv() { grep '^PALPATION tool=probe ' "$OUT/lab/$1-server.log" | tr ' ' '\n' | sed -n "s/^$2=//p"; }
near() { # NAME GOT WANT ABS REL
  awk -v g="$2" -v w="$3" -v a="$4" -v r="$5" 'BEGIN { d = g - w; if (d < 0) d = -d; t = r * (w < 0 ? -w : w);
    if (t < a) t = a; exit !(g != "" && d <= t) }' || fail "$1: report $2, server $3 (tolerance max($4, $5 rel))"
  echo "ok: $1 report $2 server $3"
}
for s in seat01 seat02 seat03; do
  [ "$(col $s partition)" = "lab/$s" ] || fail "$s: row's partition is '$(col $s partition)'"
  col "$s" identity | grep -q "^seat lab/$s; station " || fail "$s: identity '$(col $s identity)'"
  near "$s contact time" "$(col $s contact_time_s)" "$(srv $s contact_time)" 0.05 0.03
  for k in ST MPF SFT; do
    near "$s time above $k" "$(col $s time_above_${k}_s)" "$(srv $s time_above_$k)" 0.05 0.03
    [ "$(col $s crossings_$k)" = "$(srv $s crossings_$k)" ] || fail "$s: $k crossings $(col $s crossings_$k), server $(srv $s crossings_$k)"
  done
  near "$s peak force" "$(col $s peak_force_N)" "$(srv $s peak_force)" 0.02 0
  near "$s mean contact force" "$(col $s mean_contact_force_N)" "$(srv $s mean_contact_force)" 0.005 0.03
done
echo "PASS"
