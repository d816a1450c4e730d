#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Participants and roles in a recording (issue 6). usage: BUILD SRC OUT
#   1. a real session (deploy/session.sh: server, recorder, viewer, haptic)
#      on $VISCERA_DOMAIN; viscera-recinfo must list the server, haptic,
#      viewer and recorder participants with their roles (taken from each
#      process's USER_DATA), the haptic client with its tool index, and the
#      clients that quit before the end as "left";
#   2. a recording from before the participants table (table dropped with
#      sqlite3) still reads: recinfo exits 0 and says it is not recorded,
#      viscera-report accepts it.
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
RECINFO=$BUILD/client/recorder/viscera-recinfo
REPORT=$BUILD/client/report/viscera-report
fail() { echo "recorder_participants: FAIL: $*" >&2; for f in "$OUT"/*.log "$OUT"/*.txt; do [ -s "$f" ] && { echo "--- $f"; tail -20 "$f"; }; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"

VISCERA_PARTITION=test/participants bash "$SRC/deploy/session.sh" "$BUILD" "$OUT" >"$OUT/session.log" 2>&1 ||
  fail "session did not run"
"$RECINFO" "$OUT/session.db" >"$OUT/info.txt" 2>"$OUT/info.log" || fail "recinfo failed"
sed -n '/^participants (/,/^participants: /p' "$OUT/info.txt"
# one participant row per process, with role column = the announced role
for role in server haptic viewer recorder; do
  n=$(awk -v r="$role" '$1 == r && $0 ~ ("viscera role=" r " ")' "$OUT/info.txt" | wc -l)
  [ "$n" -eq 1 ] || fail "$n participant rows with role $role (expected 1)"
done
grep -Eq '^haptic .*viscera role=haptic tool=0 host=[^ ]+ pid=[0-9]+$' "$OUT/info.txt" ||
  fail "haptic participant does not announce tool=0, host and pid"
# session.sh stops the haptic client before the others: it left mid-recording
grep -Eq '^haptic +[0-9a-f]{32} +[0-9T:.Z-]+ +[0-9]{4}-' "$OUT/info.txt" || fail "the haptic client is not shown as left"
grep -q '^participants: 4$' "$OUT/info.txt" || fail "expected exactly 4 participants"
# the stored rows match the processes that ran (pids in session.sh's logs are not kept, so check the table)
[ "$(sqlite3 "$OUT/session.db" "SELECT count(*) FROM participants WHERE role IN ('server','haptic','viewer','recorder')")" = 4 ] ||
  fail "participants table does not hold the 4 roles"

echo "== a recording from before the participants table"
cp "$OUT/session.db" "$OUT/old.db"
sqlite3 "$OUT/old.db" "DROP TABLE participants" || fail "cannot drop the table"
"$RECINFO" "$OUT/old.db" >"$OUT/old_info.txt" 2>"$OUT/old_info.log" || fail "recinfo rejects a recording without participants"
grep -q 'not recorded: this recording predates participant metadata' "$OUT/old_info.txt" || fail "no 'predates' note"
grep -q '^viscera_MeshDelta ' "$OUT/old_info.txt" || fail "old recording lost its topics listing"
if [ -x "$REPORT" ]; then
  "$REPORT" --out "$OUT/report" "$OUT/old.db" >"$OUT/report.log" 2>&1 || fail "viscera-report rejects the old recording"
fi
echo "recorder_participants: PASS"
