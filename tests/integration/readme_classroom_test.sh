#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The README's "Classroom in five minutes" block, run verbatim (issue 18):
# extracted from README.md (the sh block after the classroom-block marker)
# and run by bash in a scratch directory laid out like the repository root
# (deploy/, assets/ and build/ are links to the real ones), with
# CYCLONEDDS_URI unset as a new user has it and VISCERA_DOMAIN set to this
# test's domain (the only way the block's default domain 0 moves, honoured by
# every script and binary). Asserts: the block ends by itself with status 0,
# the dashboard saw a scene in every seat and a trainee pressing in every
# seat (lab.sh's trainees palpate for the whole lab, not once at its start),
# the pause reached seat 2, the lab recorded every seat and the report was
# written.
# Then lab.sh --secure: the dashboard command it prints is run as printed:
# it sees every seat; a dashboard without identity sees none and says why.
# usage: readme_classroom_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
unset CYCLONEDDS_URI
FAIL_LOGS="$OUT/root/out/lab/*.log"
awk '/<!-- classroom-block/ { on = 1; next } on && /^```sh/ { inb = 1; next } inb && /^```/ { exit } inb' \
  "$SRC/README.md" > "$OUT/block.sh"
grep -q 'deploy/lab.sh' "$OUT/block.sh" || fail "no classroom block found in README.md"
echo "--- the block:"; cat "$OUT/block.sh"
mkdir -p "$OUT/root"
ln -s "$SRC/deploy" "$OUT/root/deploy"
ln -s "$SRC/assets" "$OUT/root/assets"
ln -s "$BUILD" "$OUT/root/build"

# Its own session, so whatever the block leaves behind can be found and killed.
(cd "$OUT/root" && exec setsid bash "$OUT/block.sh") > "$OUT/block.log" 2>&1 &
BLOCK=$!
PIDS+=("$BLOCK")
st=0
for ((t = 0; t < 900; t++)); do kill -0 "$BLOCK" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$BLOCK" 2>/dev/null; then
  pkill -KILL -s "$BLOCK" 2>/dev/null || true
  fail "the classroom block still ran after 90 s"
fi
wait "$BLOCK" || st=$?
PIDS=()
cat "$OUT/block.log"
[ $st = 0 ] || fail "the classroom block exited with $st"
grep -q "lab: seats 1..3 on domain $VISCERA_DOMAIN" "$OUT/block.log" || fail "lab.sh did not run on VISCERA_DOMAIN"
grep -q "viscera-dashboard .*--seats 3" "$OUT/block.log" || fail "lab.sh printed no dashboard command"
csv="$OUT/root/out/dashboard/dashboard.csv"
[ -f "$csv" ] || fail "the dashboard wrote no $csv"
for s in 01 02 03; do
  grep -q "^[0-9]*,[0-9.]*,lab/seat$s,1," "$csv" || fail "the dashboard never saw a scene in lab/seat$s"
  # Columns: frame, wall_s, seat, have_scene, force_n: a press is > 0.3 N.
  awk -F, -v s="lab/seat$s" '$3 == s && $5 > 0.3 { n++ } END { exit !(n > 0) }' "$csv" ||
    fail "the dashboard never saw lab/seat$s's trainee press (force_n > 0.3 N in no frame)"
done
grep -q "^applied: " "$OUT/block.log" || fail "viscera-control's pause was not applied"
[ -f "$OUT/root/out/report/report.html" ] || fail "no report written"
for s in 01 02 03; do
  grep -q "lab/seat$s" <(sqlite3 "$OUT/root/out/lab/lab.db" "SELECT DISTINCT partitions FROM writers") ||
    fail "the lab recording has nothing of lab/seat$s"
done
echo "readme block: every seat seen by the dashboard, pause applied, report written"

# --secure: the printed dashboard command, pasted (with --duration added).
(cd "$OUT/root" && exec setsid bash deploy/lab.sh --seats 2 --secure --viewers 0 --no-record --duration 14 \
  --out "$OUT/secure") > "$OUT/secure.log" 2>&1 &
LAB=$!
PIDS+=("$LAB")
for ((t = 0; t < 300; t++)); do grep -q -- "--out .*/dashboard$" "$OUT/secure.log" 2>/dev/null && break; sleep 0.1; done
line="$(grep -- "viscera-dashboard .*--out .*/dashboard$" "$OUT/secure.log" | head -1)"
[ -n "$line" ] || fail "lab.sh --secure printed no dashboard command"
echo "pasted: $line"
case "$line" in *identities/instructor/security.xml*) ;; *) fail "the printed command has no instructor identity" ;; esac
sleep 3
# The same without identity, at the same time: nothing, and the explanation.
(cd "$OUT/root" && exec build/client/dashboard/viscera-dashboard --seats 2 --out "$OUT/plain_dash" --duration 7) \
  > "$OUT/plain_dashboard.log" 2>&1 &
PLAIN=$!
PIDS+=("$PLAIN")
(cd "$OUT/root" && eval "$line --duration 8") > "$OUT/secure_dashboard.log" 2>&1 || fail "the pasted dashboard failed"
wait "$PLAIN" || fail "the dashboard without identity failed"
wait "$LAB" || fail "lab.sh --secure failed"
PIDS=()
for s in 01 02; do
  grep -q "^[0-9]*,[0-9.]*,lab/seat$s,1," "$OUT/secure/dashboard/dashboard.csv" ||
    fail "the pasted secure dashboard never saw lab/seat$s"
done
if grep -q ",lab/seat0[12],1," "$OUT/plain_dash/dashboard.csv"; then fail "a dashboard without identity saw a secure seat"; fi
cat "$OUT/plain_dashboard.log"
grep -q "nothing seen after 5 s: no seat has a server" "$OUT/plain_dashboard.log" || fail "no 'nothing seen' explanation"
grep -q "refuse a participant without identity" "$OUT/plain_dashboard.log" || fail "the secure cause was not named"
echo PASS
