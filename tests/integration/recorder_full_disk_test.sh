#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Full disk while recording. The recorder runs under a file-size limit
# (ulimit -f: writes past it fail with EFBIG, as on a full disk; the
# recorder ignores SIGXFSZ) while a real palpation session runs. Asserts:
#  - the recorder stops by itself, exit status 1 (not a signal, no sanitizer
#    report), with "disk full: recording stopped, N samples saved";
#  - viscera-recinfo reads the file alone (no -wal left next to it: the WAL
#    was checkpointed into it) and finds exactly those N samples, with no end
#    time; viscera-report gives a report of it with a warning;
#  - a second recorder killed with SIGKILL mid-session (while the probe
#    holds its press and the server publishes) leaves a file and its WAL
#    that recinfo reads and viscera-report reports, contact included.
# usage: recorder_full_disk_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-101}"; PART="fulldisk/seat01"
LIMIT_KB=1024
rm -rf "$OUT"; mkdir -p "$OUT"
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.err "$OUT"/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -5 "$f"; }; done >&2; exit 1; }
common=(--domain "$DOMAIN" --partition "$PART")

"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" "${common[@]}" \
  >"$OUT/server.out" 2>"$OUT/server.log" &
SERVER=$!; pids+=($SERVER)
await() { for _ in $(seq 600); do grep -q -- "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done; return 1; }
"$BUILD/client/recorder/viscera-recorder" "${common[@]}" --out "$OUT/killed.db" --quiet \
  >"$OUT/killed.out" 2>"$OUT/killed.err" &
KILLED=$!; pids+=($KILLED)
"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/push_hold_kidney.traj" "${common[@]}" \
  --duration 60 >"$OUT/haptic.out" 2>"$OUT/haptic.log" &
HAPTIC=$!; pids+=($HAPTIC)
# The size-limited recorder starts once the probe presses and holds (the
# server's threshold line), so that it fills up while commands and feedback
# flow at 1 kHz, however loaded the machine: started with the session, its
# SQLite WAL could reach the limit on the keyframe and the first batches
# alone, before any contact (seen in the suite: 43 samples, no ToolCommand,
# nothing to report); with a trajectory that ends, it could outlast the flow.
await "$OUT/server.log" "ST crossed up" || fail "the probe never pressed the organ"
# bash counts ulimit -f in 1024-byte blocks
( ulimit -f $LIMIT_KB; exec "$BUILD/client/recorder/viscera-recorder" "${common[@]}" --out "$OUT/full.db" --quiet ) \
  >"$OUT/full.out" 2>"$OUT/full.err" &
FULL=$!; pids+=($FULL)
# It stops by itself at the limit (60 s at most, a safety stop, not a rate).
for _ in $(seq 1 300); do kill -0 $FULL 2>/dev/null || break; sleep 0.2; done
if kill -0 $FULL 2>/dev/null; then kill -INT $FULL; fail "the recorder did not stop at the file-size limit"; fi
set +e; wait $FULL; rc=$?; set -e
# The other recorder is killed while the session still runs and the probe
# still presses, after at least the time the first one took to fill (so
# more than a second of contact): what it committed of the contact must
# survive the kill (only the last uncommitted batch, at most 200 ms, is lost).
kill -0 $HAPTIC 2>/dev/null || fail "the trainee ended before the recorder filled up"
kill -9 $KILLED
wait $KILLED 2>/dev/null || true
kill -INT $HAPTIC; wait $HAPTIC || fail "haptic client failed"
kill -INT $SERVER; wait $SERVER || true
pids=()
cat "$OUT/full.err"
[ $rc -eq 1 ] || fail "recorder at the size limit exited $rc, want 1"
! grep -q "AddressSanitizer\|runtime error" "$OUT/full.err" || fail "sanitizer report from the recorder"
n=$(sed -n 's/^recorder: disk full: recording stopped, \([0-9]*\) samples saved in .*/\1/p' "$OUT/full.err")
[ -n "$n" ] && [ "$n" -gt 0 ] || fail "no 'disk full: recording stopped, N samples saved' message"
ls -l "$OUT"/full.db* "$OUT"/killed.db*
[ ! -s "$OUT/full.db-wal" ] || fail "the stopped recording left its WAL: the .db alone is incomplete"
size=$(stat -c %s "$OUT/full.db")
[ "$size" -le $((LIMIT_KB * 1024)) ] || fail "full.db is $size bytes, beyond the limit"

# The .db alone (copied elsewhere) holds every saved sample.
mkdir -p "$OUT/copy" && cp "$OUT/full.db" "$OUT/copy/full.db"
"$BUILD/client/recorder/viscera-recinfo" "$OUT/copy/full.db" >"$OUT/info_full.txt" 2>"$OUT/info_full.err" \
  || fail "recinfo cannot read the stopped recording"
cat "$OUT/info_full.txt"
total=$(sed -n 's/^total: \([0-9]*\) samples.*/\1/p' "$OUT/info_full.txt")
[ "$total" = "$n" ] || fail "recinfo finds $total samples, the recorder said $n"
"$BUILD/client/report/viscera-report" --out "$OUT/report_full" "$OUT/copy/full.db" 2>"$OUT/report_full.err" \
  || fail "no report of the stopped recording"
grep -q "warning: .*no end time" "$OUT/report_full.err" || fail "report: no warning that the recording stopped early"

# The killed recorder: its file plus WAL read, and give a report with contact.
"$BUILD/client/recorder/viscera-recinfo" "$OUT/killed.db" >"$OUT/info_killed.txt" 2>"$OUT/info_killed.err" \
  || fail "recinfo cannot read the killed recording"
"$BUILD/client/report/viscera-report" --out "$OUT/report_killed" "$OUT/killed.db" 2>"$OUT/report_killed.err" \
  || fail "no report of the killed recording"
cat "$OUT/report_killed.err"
ct=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next } { print $c["contact_time_s"] }' \
  "$OUT/report_killed/report.csv")
awk -v c="$ct" 'BEGIN { exit !(c > 0.1) }' || fail "killed recording: contact time $ct, want the contact before the kill"
echo PASS
