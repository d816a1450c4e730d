#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Two tools on one organ over DDS (issue 4): two haptic clients drive the two
# probes of two_tools.yaml (kidney + spleen) so their tips meet above and on
# the kidney. Asserts: in every recorded pair of ContactFeedback samples of
# the same step the tips the clients are told are at least the sum of the
# radii (3 + 4 mm) apart (float tolerance 1 um); both clients rendered
# forces, none above the 4 N device limit or non-finite; the two met (some
# pair within 1 mm of the limit); no rollback. usage: two_tools_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log "$OUT"/*.out; do echo "--- $f"; tail -5 "$f"; done >&2; exit 1; }
. "$(dirname "$0")/tools_session.sh"
tools_session "$BUILD" "$OUT" "$SRC/assets/scenes/two_tools.yaml" \
  "0:$SRC/assets/trajectories/palpate_kidney.traj" "1:$SRC/assets/trajectories/two_tools_probe2.traj" \
  || fail "session did not run"
"$BUILD/tests/integration/rec_tools" "$OUT/session.db" > "$OUT/rec.txt" || fail "rec_tools failed"
cat "$OUT/rec.txt"; grep -E '^(SUMMARY|TOOL) ' "$OUT/server.out"
val() { echo "$1" | tr ' ' '\n' | sed -n "s/^$2=//p"; }
p=$(grep '^FEEDBACK_PAIRS ' "$OUT/rec.txt")
awk -v n="$(val "$p" n)" -v d="$(val "$p" min_tip_distance)" 'BEGIN { exit !(n > 500 && d >= 0.007 - 1e-6 && d < 0.008) }' \
  || fail "tips closer than 7 mm, or never met, or too few pairs: $p"
for t in 0 1; do
  awk -F, 'NR > 1 { f = sqrt($5*$5 + $6*$6 + $7*$7); if (f != f || f > 4.001) bad++; if (f > 0.2) on++ }
           END { exit !(bad == 0 && on > 100) }' "$OUT/haptic$t.csv" || fail "tool $t forces not sane (csv)"
done
grep -q 'rollbacks=0 ' "$OUT/server.out" || fail "rollbacks"
echo "PASS"
