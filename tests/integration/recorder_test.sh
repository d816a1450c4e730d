#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
# Recorder integration test driver (registered by recorder.cmake).
# usage: recorder_test.sh RECORDER RECINFO REC_PUB REC_CHECK WORKDIR DOMAIN
#   1. late join + normal stop: rec_pub writes MeshState keyframes, then the
#      recorder starts, then 500 ToolCommand, MeshDelta and a dispose, plus a
#      topic without XTypes type information that the recorder must report
#      and skip; SIGINT stops the recorder; recinfo --check-monotonic and
#      rec_check verify;
#   2. the recorder refuses to overwrite an existing recording;
#   3. kill -9 of the recorder mid-session leaves a file recinfo reads;
#   4. recinfo on garbage, a truncated copy and a missing file: clear error
#      naming the file, exit status 1, no crash.
# Needs CYCLONEDDS_URI (loopback config) in the environment.
set -u
REC=$1
RECINFO=$2
PUB=$3
CHECK=$4
WORK=$5
DOMAIN=$6
PART=viscera/rectest
TOOLS=500
PIDS=""

cleanup() {
  for p in $PIDS; do kill -9 "$p" 2>/dev/null; done
}
trap cleanup EXIT

fail() {
  echo "recorder_test: FAIL: $*" >&2
  for f in "$WORK"/*.err; do
    [ -s "$f" ] && { echo "--- $f" >&2; tail -n 20 "$f" >&2; }
  done
  exit 1
}

wait_for_file() {
  i=0
  while [ ! -e "$1" ]; do
    i=$((i + 1))
    [ $i -gt 300 ] && return 1
    sleep 0.1
  done
  return 0
}

[ -n "${CYCLONEDDS_URI:-}" ] || fail "CYCLONEDDS_URI is not set (loopback config expected)"
rm -rf "$WORK"
mkdir -p "$WORK" || fail "cannot create $WORK"

echo "== 1. late join, streams, dispose, SIGINT"
"$PUB" --domain "$DOMAIN" --partition "$PART" --ready "$WORK/ready1" --tools $TOOLS --untyped \
  >"$WORK/pub1.out" 2>"$WORK/pub1.err" &
PUB_PID=$!
PIDS="$PIDS $PUB_PID"
wait_for_file "$WORK/ready1" || fail "rec_pub never wrote its keyframes"
# keyframes exist before the recorder does: it must get them as a late joiner
sleep 0.2
"$REC" --domain "$DOMAIN" --partition "$PART" --out "$WORK/session.db" --scene rectest \
  >"$WORK/rec1.out" 2>"$WORK/rec1.err" &
REC_PID=$!
PIDS="$PIDS $REC_PID"
wait $PUB_PID || fail "rec_pub failed"
DELTAS=$(sed -n 's/^PUB tools=[0-9]* deltas=\([0-9]*\)$/\1/p' "$WORK/pub1.out")
[ -n "$DELTAS" ] || fail "rec_pub printed no PUB line"
sleep 0.3
kill -INT $REC_PID
wait $REC_PID
rc=$?
[ $rc -eq 0 ] || fail "recorder exited with $rc after SIGINT"
cat "$WORK/rec1.err"
cat "$WORK/rec1.out"
grep -q '^SUMMARY samples=[0-9]* topics=3 bytes=[0-9]*$' "$WORK/rec1.out" || fail "no SUMMARY line with 3 topics"
grep -q "^recorder: wrote [0-9]* samples of 3 topics to $WORK/session.db\$" "$WORK/rec1.err" ||
  fail "no 'wrote' line"
grep -q "^recorder: topic rectest_Untyped: NOT recorded: writer sent no XTypes type information" "$WORK/rec1.err" ||
  fail "the topic without type information was not reported"
[ ! -e "$WORK/session.db-wal" ] || fail "WAL left behind after a clean stop"
"$RECINFO" "$WORK/session.db" --check-monotonic >"$WORK/info1.txt" 2>"$WORK/info1.err" ||
  fail "recinfo --check-monotonic failed on the recording"
cat "$WORK/info1.txt"
"$RECINFO" "$WORK/session.db" --topic viscera_ToolCommand >/dev/null 2>"$WORK/info1t.err" || fail "recinfo --topic failed"
"$CHECK" "$WORK/session.db" $TOOLS "$DELTAS" "$PART" "$DOMAIN" 2>"$WORK/check1.err" || fail "rec_check failed"

echo "== 2. no overwrite"
"$REC" --domain "$DOMAIN" --partition "$PART" --out "$WORK/session.db" --duration 1 --quiet \
  >/dev/null 2>"$WORK/rec2.err"
rc=$?
[ $rc -eq 1 ] || fail "recorder on an existing file exited with $rc, expected 1"
grep -q "session.db: file exists" "$WORK/rec2.err" || fail "no 'file exists' message"
"$CHECK" "$WORK/session.db" $TOOLS "$DELTAS" "$PART" "$DOMAIN" >/dev/null 2>&1 || fail "recording damaged by refused overwrite"

echo "== 3. kill -9 mid-session"
"$PUB" --domain "$DOMAIN" --partition "$PART" --ready "$WORK/ready3" --tools 3000 --rate 1000 \
  >"$WORK/pub3.out" 2>"$WORK/pub3.err" &
PUB_PID=$!
PIDS="$PIDS $PUB_PID"
wait_for_file "$WORK/ready3" || fail "rec_pub never wrote its keyframes"
"$REC" --domain "$DOMAIN" --partition "$PART" --out "$WORK/killed.db" --quiet >"$WORK/rec3.out" 2>"$WORK/rec3.err" &
REC_PID=$!
PIDS="$PIDS $REC_PID"
sleep 2
kill -9 $REC_PID
wait $REC_PID 2>/dev/null
wait $PUB_PID || fail "rec_pub failed in the kill -9 run"
ls -l "$WORK"/killed.db*
"$RECINFO" "$WORK/killed.db" --check-monotonic >"$WORK/info3.txt" 2>"$WORK/info3.err"
rc=$?
cat "$WORK/info3.txt"
[ $rc -eq 0 ] || fail "recinfo exited $rc on the killed recording"
grep -q '^end: *(none' "$WORK/info3.txt" || fail "killed recording should have no end time"
n=$(awk '$1 == "viscera_ToolCommand" { print $3 }' "$WORK/info3.txt")
[ -n "$n" ] && [ "$n" -gt 100 ] || fail "killed recording holds too few ToolCommand samples (${n:-none})"

echo "== 4. recinfo on what is not a recording"
expect_bad() { # file, message part
  "$RECINFO" "$1" >/dev/null 2>"$WORK/bad.err"
  rc=$?
  cat "$WORK/bad.err"
  [ $rc -eq 1 ] || fail "recinfo on $1 exited $rc, expected 1"
  grep -q "$1" "$WORK/bad.err" || fail "recinfo error does not name $1"
  grep -q "$2" "$WORK/bad.err" || fail "recinfo error on $1 lacks '$2'"
}
printf 'this is not a database\n' >"$WORK/garbage.db"
expect_bad "$WORK/garbage.db" "not a SQLite database"
expect_bad "$WORK/missing.db" "No such file"
head -c 20000 "$WORK/session.db" >"$WORK/truncated.db"
expect_bad "$WORK/truncated.db" "damaged"
sqlite3 "$WORK/other.db" "CREATE TABLE t (x);" 2>/dev/null &&
  expect_bad "$WORK/other.db" "not a viscera recording"

echo "recorder_test: PASS"
