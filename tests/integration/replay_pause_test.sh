#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Replay pause (issue 6). usage: BUILD SRC OUT; domains $VISCERA_DOMAIN
# (recorded session) and $VISCERA_DOMAIN+1 (replay target).
#   A session is recorded, then replayed into the second domain with
#   --pause-at P (1 s after the recording's first MeshDelta: on a loaded
#   machine the server may publish its first one a second or more after the
#   recorder started) while a second recorder listens; 2 s after the replay says
#   "paused", SIGUSR1 resumes it. In the second recording, the delay
#   arrival - source timestamp of MeshDelta (a ~30 Hz stream) must jump by
#   >= 1.8 s at the pause point and stay there: a burst of the samples that
#   fell due while paused would bring it back down. The whole replay takes
#   at least the recording span + the pause, and the progress line said
#   "(paused)".
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
D1=${VISCERA_DOMAIN:-179}
D2=$((D1 + 1))
REPLAY=$BUILD/client/recorder/viscera-replay
RECORDER=$BUILD/client/recorder/viscera-recorder
PART=replay/pause
PIDS=""
cleanup() { for p in $PIDS; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "replay_pause: FAIL: $*" >&2; for f in "$OUT"/*.log; do [ -s "$f" ] && { echo "--- $f"; tail -20 "$f"; }; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"

VISCERA_DOMAIN=$D1 VISCERA_PARTITION=test/pause bash "$SRC/deploy/session.sh" "$BUILD" "$OUT/session" \
  >"$OUT/session.log" 2>&1 || fail "session did not run"
DB=$OUT/session/session.db

q() { sqlite3 "$1" "$2"; }
T0=$(q "$DB" "SELECT start_wall_ns FROM session")
FIRST=$(q "$DB" "SELECT (min(s.source_ts_ns) - $T0) / 1e9 FROM samples s JOIN topics t ON t.id = s.topic_id
  WHERE t.name = 'viscera_MeshDelta' AND s.kind = 0")
[ -n "$FIRST" ] || fail "the recorded session has no MeshDelta"
PAUSE=$(awk -v f="$FIRST" 'BEGIN { printf "%.1f", f + 1.0 }')
echo "first MeshDelta at $FIRST s of the recording: pause at $PAUSE s"
"$RECORDER" --domain "$D2" --partition "$PART" --out "$OUT/replayed.db" --quiet >"$OUT/rec2.out" 2>"$OUT/rec2.log" &
RPID=$!; PIDS="$PIDS $RPID"
sleep 1
start=$(date +%s.%N)
"$REPLAY" "$DB" --domain "$D2" --partition "$PART" --pause-at "$PAUSE" >"$OUT/replay.out" 2>"$OUT/replay.log" &
PPID_=$!; PIDS="$PIDS $PPID_"
for _ in $(seq 1 300); do grep -q '^replay: paused at sim time' "$OUT/replay.log" && break; sleep 0.1; done
grep -q "^replay: paused at sim time ${PAUSE%.*}\\." "$OUT/replay.log" || fail "replay did not pause at sim time $PAUSE"
sleep 2.5  # the progress line comes once a second: let one say "(paused)"
kill -USR1 $PPID_
wait $PPID_ || fail "replay exited with an error"
end=$(date +%s.%N)
cat "$OUT/replay.log"
grep -q '(paused)$' "$OUT/replay.log" || fail "no progress line says (paused)"
grep -q '^replay: resumed after [2-9]\.[0-9] s paused (SIGUSR1)' "$OUT/replay.log" || fail "no resume line"
sleep 0.5
kill -INT $RPID; wait $RPID || fail "second recorder failed"

SPAN=$(q "$DB" "SELECT (max(source_ts_ns) - $T0) / 1e9 FROM samples WHERE kind = 0")
awk -v s="$start" -v e="$end" -v span="$SPAN" 'BEGIN { d = e - s; printf "replay wall time %.2f s, recording span %.2f s\n", d, span; exit !(d >= span + 2.0) }' ||
  fail "replay took less than the recording span + the 2 s pause"
# delay = arrival - source timestamp, per MeshDelta sample, with its recording time
delays() {
  q "$OUT/replayed.db" "SELECT (s.source_ts_ns - $T0) / 1e9, (s.recv_wall_ns - s.source_ts_ns) / 1e9 FROM samples s
    JOIN topics t ON t.id = s.topic_id WHERE t.name = 'viscera_MeshDelta' AND s.kind = 0 ORDER BY s.id" | tr '|' ' '
}
delays >"$OUT/delays.txt"
read -r nb before na amin amax < <(awk -v p="$PAUSE" '
  $1 > p - 0.5 && $1 < p - 0.02 { nb++; sb += $2 }
  $1 > p + 0.02 { na++; if (na == 1 || $2 < mn) mn = $2; if (na == 1 || $2 > mx) mx = $2 }
  END { printf "%d %.3f %d %.3f %.3f\n", nb, nb ? sb / nb : 0, na, mn, mx }' "$OUT/delays.txt")
echo "MeshDelta before pause: $nb samples, mean delay $before s; after: $na samples, delay $amin..$amax s"
[ "$nb" -ge 3 ] && [ "$na" -ge 50 ] || fail "too few MeshDelta samples replayed ($nb before, $na after)"
awk -v b="$before" -v mn="$amin" 'BEGIN { exit !(mn - b >= 1.8) }' ||
  fail "samples after the pause arrived less than 1.8 s later than before (burst at resume?)"
awk -v mn="$amin" -v mx="$amax" 'BEGIN { exit !(mx - mn < 1.0) }' ||
  fail "delay after resume drifts by $(awk -v a="$amin" -v b="$amax" 'BEGIN{print b-a}') s: original timing not kept"
# A --seek or --pause-at past the recording's last sample is not refused
# (nothing is left to play) but said: before, the replay ended silently.
"$REPLAY" "$DB" --domain "$D2" --partition "$PART/past" --seek 100000 --pause-at 200000 --quiet \
  >"$OUT/past.out" 2>"$OUT/past.log" || fail "replay past the end exited with an error"
grep -q -- "--seek 100000 s is past the recording's last sample" "$OUT/past.log" || fail "no word of --seek past the end"
grep -q -- "--pause-at 200000 s is past the recording's last sample .*: it will not pause" "$OUT/past.log" ||
  fail "no word of --pause-at past the end"
echo "replay_pause: PASS"
