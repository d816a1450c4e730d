#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The whole loop end to end: server, recorder, viewer and scripted haptic
# client as separate processes over DDS on loopback. Asserts: contact force
# above zero while the probe is inside and zero after release; the viewer's
# frame during contact differs from the rest frame in the contact region;
# the recording holds ToolCommand and MeshDelta samples with increasing
# timestamps. usage: session_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do echo "--- $f"; tail -5 "$f"; done >&2; exit 1; }

# Tools hidden so frame differences come from the organ only.
VIEWER_ARGS="--interval-ms 100 --tools off" bash "$SRC/deploy/session.sh" "$BUILD" "$OUT" || fail "session did not run"

# 1. Force: above zero during contact, zero at the end after release.
inside=$(awk -F, 'NR>1 && $8==1 { f=sqrt($5*$5+$6*$6+$7*$7); if (f>0.05) n++ } END { print n+0 }' "$OUT/haptic_force.csv")
tail_force=$(tail -n 200 "$OUT/haptic_force.csv" | awk -F, '{ f=sqrt($5*$5+$6*$6+$7*$7); if (f>m) m=f } END { print m+0 }')
echo "ticks with force > 0.05 N in contact: $inside; max force over the last 200 ticks: $tail_force N"
[ "$inside" -gt 100 ] || fail "no contact force while the probe was inside"
awk -v f="$tail_force" 'BEGIN { exit !(f == 0) }' || fail "force not back to zero after release ($tail_force N)"

# 2. Frames: the contact frame differs from the rest frame around the contact point.
csv="$OUT/frames/frames.csv"
[ -f "$csv" ] || fail "viewer wrote no frames.csv"
rest=$(awk -F, 'NR==2 { print $2 }' "$csv")
read -r contact px py < <(awk -F, 'NR>1 && $6==1 && $10>=0 { if ($7>m) { m=$7; line=$2" "$10" "$11 } } END { print line }' "$csv")
[ -n "${contact:-}" ] || fail "no frame was written during contact"
echo "rest frame $rest, contact frame $contact at pixel ($px, $py)"
read -r diff < <("$BUILD/tests/integration/img_diff" "$OUT/frames/$rest" "$OUT/frames/$contact" "${px%.*}" "${py%.*}" 40)
echo "$diff"
win=$(echo "$diff" | sed 's/.*window_mean=\([^ ]*\).*/\1/')
outside=$(echo "$diff" | sed 's/.*outside_mean=\([^ ]*\).*/\1/')
awk -v w="$win" -v o="$outside" 'BEGIN { exit !(w > 1.0 && w > 4 * o) }' \
  || fail "contact frame does not differ from the rest frame in the contact region"

# 3. Recording: ToolCommand and MeshDelta present, timestamps increasing.
"$BUILD/client/recorder/viscera-recinfo" "$OUT/session.db" --check-monotonic > "$OUT/recinfo.txt" || fail "recinfo --check-monotonic failed"
cat "$OUT/recinfo.txt"
# The recording names the scene by the scene file's `scene:` name.
grep -q "^scene: *kidney-palpation$" "$OUT/recinfo.txt" || fail "recording does not name its scene (kidney-palpation)"
for topic in viscera_ToolCommand viscera_MeshDelta viscera_MeshState; do
  grep -q "$topic" "$OUT/recinfo.txt" || fail "recording lacks $topic"
done
echo "PASS"
