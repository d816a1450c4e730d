#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# deploy/lab.sh --one-server --seat-threads 1 (issue 17 item 6) on loopback:
# seats 2-3 (--first 2) in one viscera-server, both stepped by one physics
# thread (server/session/seat_group.h), a scripted trainee and a
# viewer per seat, the lab recorder, until Ctrl-C. Asserts: one server
# process in the lab, serving both seats (each seat recorded from its own
# partition and participant, no writer in two partitions, ToolCommands in
# both), every viewer wrote frames, both trainees felt force, the process's
# log split into seat02-server.log and seat03-server.log with each seat's
# figures, the lab's summary line per seat with its step time, exit 0 after
# SIGINT with nothing left running; the lab's recording re-simulates each
# seat bit for bit with viscera-resim --partition, and without it names the
# two sessions and exits 2. (The secure variant: lab_one_server_secure.)
# usage: lab_one_server_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
# shellcheck source=lab_checks.sh
. "$(dirname "$0")/lab_checks.sh"
L=""
cleanup() {
  local p
  [ -n "$L" ] || return 0
  kill -TERM "$L" 2>/dev/null || true
  sleep 3
  for p in $(ps -o pid= -s "$L" 2>/dev/null); do kill -KILL "$p" 2>/dev/null || true; done
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  for f in "$OUT"/*.out "$OUT"/*/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -6 "$f"; }; done >&2
  exit 1
}
rm -rf "$OUT"; mkdir -p "$OUT"
command -v sqlite3 > /dev/null || fail "sqlite3 missing (deploy/install_deps.sh installs it)"
launch_lab L "$OUT/lab.out" --out "$OUT/l" --one-server --seat-threads 1 --first 2 --seats 2 --trainees --viewers 1 \
  --duration 0
wait_trainees "$L" "the lab" "$OUT"/l/seat02-haptic.log "$OUT"/l/seat03-haptic.log
servers=$(ps -o args= -s "$L" | grep -c '^[^ ]*/viscera-server ' || true)
[ "$servers" = 1 ] || fail "$servers server processes in the lab, expected one for both seats"
srv=$(ps -o pid=,args= -s "$L" | awk '$2 ~ /\/viscera-server$/ { print $1 }')
threads=$(cat /proc/"$srv"/task/*/comm 2> /dev/null | tr '\n' ' ')
case " $threads" in *" seats02-03 "*) ;; *) fail "no physics thread 'seats02-03' for both seats: $threads" ;; esac
sleep 1 # a few more MeshDeltas of every seat reach the recorder
kill -INT "$L"
for ((t = 0; t < 300; t++)); do kill -0 "$L" 2>/dev/null || break; sleep 0.1; done
kill -0 "$L" 2>/dev/null && fail "lab.sh still running 30 s after SIGINT"
st=0; wait "$L" || st=$?
cat "$OUT/lab.out"
[ "$st" = 0 ] || fail "the lab exited with $st after SIGINT, expected 0"
expect_nothing_left "$L" "the lab"
L=""

DB="$OUT/l/lab.db"
expect_lab_recorded "$DB" 2 3 02 03
for s in seat02 seat03; do
  expect_frames "$OUT/l/$s-frames1"
  expect_trainee_force "$OUT/l/$s-haptic.log"
  grep -q '^server: [0-9]* steps, step time median' "$OUT/l/$s-server.log" || fail "no step figures in $s-server.log"
  grep -q '^SUMMARY steps=[0-9]' "$OUT/l/$s-server.log" || fail "no SUMMARY line in $s-server.log"
  grep -Eq "^  $s: frames [1-9][0-9]*, trainee peak force [0-9.]+ N, step time median [0-9.]+ us" "$OUT/lab.out" ||
    fail "the lab's summary has no full line for $s"
done
# The lab's one recording holds both seats' sessions: viscera-resim asks
# which one, and re-simulates each bit for bit.
rc=0; "$BUILD/server/viscera-resim" "$DB" --quiet > "$OUT/resim_any.out" 2>&1 || rc=$?
[ "$rc" = 2 ] || fail "viscera-resim on the two-seat recording without --partition exited $rc, not 2"
grep -q "holds 2 sessions (partitions lab/seat02, lab/seat03): choose one with --partition" "$OUT/resim_any.out" ||
  fail "viscera-resim did not name the sessions: $(cat "$OUT/resim_any.out")"
for s in seat02 seat03; do
  "$BUILD/server/viscera-resim" "$DB" --quiet --partition "lab/$s" > "$OUT/resim_$s.out" 2>&1 ||
    fail "viscera-resim --partition lab/$s failed: $(tail -3 "$OUT/resim_$s.out")"
  grep -q '^RESIM PASS .*bit_exact=1' "$OUT/resim_$s.out" || fail "lab/$s not re-simulated bit for bit: $(grep RESIM "$OUT/resim_$s.out")"
  grep -q "^INPUTS mode=applied commands=[1-9][0-9]* .* lost=0" "$OUT/resim_$s.out" ||
    fail "lab/$s: $(grep INPUTS "$OUT/resim_$s.out")"
done
expect_logs "$OUT/l" recorder seats-server seat02-viewer1 seat02-haptic seat03-viewer1 seat03-haptic
echo PASS
