#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-report end to end. Records two whole sessions of the default scene
# (probe thresholds ST 0.5, MPF 0.8, SFT 1.5 N) with the expert and the
# novice palpation trajectories, runs viscera-report on both and asserts:
#  - report.csv has two rows whose figures match each server's PALPATION exit
#    line: times (contact, above ST/MPF/SFT) within 0.05 s or 3 %, peak within
#    0.02 N, mean contact force within 3 %, crossings equal; the path within
#    3 % of the trajectory's length and not below the server's (which counts
#    only the commands it applied, one per step).
#    (The report replays the recorded ContactFeedback through the server's
#    threshold tracker; the tolerance covers feedback samples a loaded
#    machine's recorder may drop: ContactFeedback is best-effort.)
#  - the novice spent longer above MPF than the expert, pressed past MPF and
#    harder than the expert, and took longer;
#  - report.html exists, is self-contained (PNG data URIs: 2 force charts and
#    the comparison charts), names both trainees;
#  - a truncated copy of a recording still gives a report (exit 0) with a
#    warning on stderr and in the HTML, its row marked incomplete;
#  - a foreign SQLite file and a file of random bytes give a clear error and
#    exit 1; mixed with a good recording, the good one is still reported.
# usage: report_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
REPORT="$BUILD/client/report/viscera-report"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*/*.log "$OUT"/*.err; do [ -f "$f" ] && { echo "--- $f"; tail -5 "$f"; }; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"

for who in expert novice; do
  VIEWER_ARGS="--interval-ms 1000" bash "$SRC/deploy/session.sh" "$BUILD" "$OUT/$who" \
    "$SRC/assets/scenes/default.yaml" "$SRC/assets/trajectories/palpate_kidney_$who.traj" || fail "$who session did not run"
  grep '^PALPATION tool=probe ' "$OUT/$who/server.out" || fail "$who: server printed no PALPATION line"
done

"$REPORT" --out "$OUT/report" --label "expert=$OUT/expert/session.db" --label "novice=$OUT/novice/session.db" \
  2> "$OUT/report.err" || fail "viscera-report failed on two good recordings"
cat "$OUT/report.err"
CSV="$OUT/report/report.csv"; HTML="$OUT/report/report.html"
[ -f "$CSV" ] && [ -f "$HTML" ] || fail "report.csv or report.html missing"
cat "$CSV"
[ "$(tail -n +2 "$CSV" | wc -l)" -eq 2 ] || fail "report.csv should have 2 rows"

# column VALUE of the row whose label is LABEL
col() { awk -F, -v lab="\"$1\"" -v name="$2" 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  $1 == lab { v = $c[name]; gsub(/"/, "", v); print v }' "$CSV"; }
srv() { grep '^PALPATION tool=probe ' "$OUT/$1/server.out" | tr ' ' '\n' | sed -n "s/^$2=//p"; }
near() { # NAME GOT WANT ABS REL
  awk -v g="$2" -v w="$3" -v a="$4" -v r="$5" 'BEGIN { d = g - w; if (d < 0) d = -d; t = r * (w < 0 ? -w : w);
    if (t < a) t = a; exit !(g != "" && d <= t) }' || fail "$1: report $2, server $3 (tolerance max($4, $5 rel))"
  echo "ok: $1 report $2 server $3"
}
for who in expert novice; do
  near "$who contact time" "$(col $who contact_time_s)" "$(srv $who contact_time)" 0.05 0.03
  for k in ST MPF SFT; do
    near "$who time above $k" "$(col $who time_above_${k}_s)" "$(srv $who time_above_$k)" 0.05 0.03
    [ "$(col $who crossings_$k)" = "$(srv $who crossings_$k)" ] || fail "$who: $k crossings $(col $who crossings_$k), server $(srv $who crossings_$k)"
  done
  near "$who peak force" "$(col $who peak_force_N)" "$(srv $who peak_force)" 0.02 0
  near "$who mean contact force" "$(col $who mean_contact_force_N)" "$(srv $who mean_contact_force)" 0.005 0.03
  # Path: the report sums every recorded command, the server only the ones
  # it applied (one per step: a server running behind on a loaded machine
  # skips commands and cuts corners). So the report must match the
  # trajectory's own length and be at least the server's.
  traj_cm=$(awk '!/^#/ && NF >= 4 { if (n++) d += sqrt(($2-x)^2 + ($3-y)^2 + ($4-z)^2); x = $2; y = $3; z = $4 }
    END { print d * 100 }' "$SRC/assets/trajectories/palpate_kidney_$who.traj")
  near "$who path length (cm) against the trajectory" "$(col $who path_length_cm)" "$traj_cm" 0.1 0.03
  awk -v r="$(col $who path_length_cm)" -v s="$(srv $who path_length)" 'BEGIN { exit !(r >= 0.97 * s * 100) }' \
    || fail "$who: report path $(col $who path_length_cm) cm below the server's $(srv $who path_length) m"
  [ "$(col $who complete)" = 1 ] || fail "$who: a clean recording marked incomplete"
  [ "$(col $who crossings_source)" = events ] || fail "$who: crossings not taken from the recorded events"
done
# Times are simulated time: on a machine so loaded that the server runs far
# behind real time it simulates only part of each trajectory, so the
# comparison asserts the order, not amounts.
awk -v n="$(col novice time_above_MPF_s)" -v e="$(col expert time_above_MPF_s)" 'BEGIN { exit !(n > e) }' \
  || fail "novice time above MPF $(col novice time_above_MPF_s) should exceed the expert's $(col expert time_above_MPF_s)"
awk -v n="$(col novice peak_force_N)" -v e="$(col expert peak_force_N)" -v mpf="$(col expert MPF_N)" \
  'BEGIN { exit !(n > mpf && n > e) }' || fail "the novice should press past MPF and harder than the expert"
awk -v n="$(col novice operation_time_s)" -v e="$(col expert operation_time_s)" 'BEGIN { exit !(n > e) }' \
  || fail "the novice's operation time should be longer"

imgs=$(grep -o 'src="data:image/png;base64,[A-Za-z0-9+/]\{200\}' "$HTML" | wc -l)
[ "$imgs" -ge 14 ] || fail "report.html has $imgs embedded PNGs, want 2 force charts + 12 comparison charts"
grep -q '<h2 id=s[0-9]*[^>]*>expert</h2>' "$HTML" && grep -q '<h2 id=s[0-9]*[^>]*>novice</h2>' "$HTML" &&
  grep -q '<h2 id=comparison>Comparison</h2>' "$HTML" \
  || fail "report.html lacks a trainee or the comparison section"
! grep -q 'src="[^d]' "$HTML" || fail "report.html refers to an external file"
for f in "$OUT"/report/*.png; do [ "$(head -c 8 "$f" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "$f is not a PNG"; done

# A truncated copy (60 % of the file): a report from what is left, with a warning.
sz=$(stat -c %s "$OUT/novice/session.db")
cp "$OUT/novice/session.db" "$OUT/truncated.db"
truncate -s $((sz * 6 / 10)) "$OUT/truncated.db"
"$REPORT" --out "$OUT/report_trunc" "$OUT/truncated.db" 2> "$OUT/trunc.err" || fail "a truncated recording gave no report"
cat "$OUT/trunc.err"
grep -q "warning: .*truncated.db: truncated or damaged" "$OUT/trunc.err" || fail "no truncation warning on stderr"
grep -q 'class=warn' "$OUT/report_trunc/report.html" || fail "no warning in the truncated recording's HTML"
[ "$(tail -n +2 "$OUT/report_trunc/report.csv" | wc -l)" -eq 1 ] || fail "truncated: no CSV row"
CSV="$OUT/report_trunc/report.csv"
[ "$(col truncated complete)" = 0 ] || fail "truncated recording not marked incomplete"
awk -v c="$(col truncated contact_time_s)" 'BEGIN { exit !(c > 0) }' || fail "truncated: no contact left to report"

# Foreign files: clear errors, exit 1, nothing written.
sqlite3 "$OUT/foreign.db" "CREATE TABLE patients (name TEXT); INSERT INTO patients VALUES ('x');"
head -c 65536 /dev/urandom > "$OUT/random.db"
for f in foreign random; do
  set +e; "$REPORT" --out "$OUT/report_$f" "$OUT/$f.db" 2> "$OUT/$f.err"; rc=$?; set -e
  cat "$OUT/$f.err"
  [ $rc -eq 1 ] || fail "$f file: exit $rc, want 1"
  [ ! -f "$OUT/report_$f/report.csv" ] || fail "$f file: a report was written"
done
grep -q "foreign.db: a SQLite database but not a viscera recording" "$OUT/foreign.err" || fail "foreign SQLite: unclear error"
grep -q "random.db: not a SQLite database" "$OUT/random.err" || fail "random bytes: unclear error"
# Mixed: the good recording is still reported, the exit status says one failed.
set +e; "$REPORT" --out "$OUT/report_mixed" "$OUT/expert/session.db" "$OUT/random.db" 2> "$OUT/mixed.err"; rc=$?; set -e
[ $rc -eq 1 ] || fail "mixed input: exit $rc, want 1"
[ "$(tail -n +2 "$OUT/report_mixed/report.csv" | wc -l)" -eq 1 ] || fail "mixed input: the good recording was not reported"
echo PASS
