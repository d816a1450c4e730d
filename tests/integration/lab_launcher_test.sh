#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# deploy/lab.sh end to end (issue 7), on loopback, as two launches sharing one
# domain, the way a lab spreads over two machines (--first/--seats):
#   A: seats 1-2, a scripted trainee and a viewer per seat, the lab recorder,
#      running until stopped; stopped with SIGINT (Ctrl-C) once both trainees
#      are done: it must stop every process cleanly and exit 0;
#   B: seats 3-4 (--first 3), no recorder, no viewer; one of its servers is
#      frozen (SIGSTOP) and B gets SIGTERM: after the grace
#      (VISCERA_LAB_STOP_GRACE=2) it must SIGKILL the frozen server, name it
#      and exit 1.
# Asserts: A's one recorder holds all four seats, each server in its own
# partition (MeshDelta from lab/seat01..04, one server participant per seat,
# no writer in two partitions); the trainees' ToolCommands only in seats 1-2;
# every viewer wrote frames; both trainees felt force; a log per process; the
# recording was closed; nothing either launch started is left running.
# usage: lab_launcher_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
# shellcheck source=lab_checks.sh
. "$(dirname "$0")/lab_checks.sh"
LABS=()
cleanup() {
  local s p
  [ ${#LABS[@]} -gt 0 ] || return 0
  for s in "${LABS[@]}"; do kill -TERM "$s" 2>/dev/null || true; done
  sleep 3
  for s in "${LABS[@]}"; do
    for p in $(ps -o pid= -s "$s" 2>/dev/null); do kill -KILL "$p" 2>/dev/null || true; done
  done
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  for f in "$OUT"/*.out "$OUT"/*/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -6 "$f"; }; done >&2
  exit 1
}
# wait_exit PID SECONDS: the exit status of a lab.sh into ST, failing if it hangs.
wait_exit() {
  local t
  for ((t = 0; t < $2 * 10; t++)); do
    if ! kill -0 "$1" 2>/dev/null; then
      ST=0
      wait "$1" || ST=$?
      return
    fi
    sleep 0.1
  done
  fail "lab.sh (pid $1) still running $2 s after it was told to stop"
}
rm -rf "$OUT"; mkdir -p "$OUT"
command -v sqlite3 > /dev/null || fail "sqlite3 missing (deploy/install_deps.sh installs it)"
export VISCERA_LAB_STOP_GRACE=2

launch_lab A "$OUT/lab_a.out" --out "$OUT/a" --seats 2 --trainees --viewers 1 --duration 0
LABS+=("$A")
launch_lab B "$OUT/lab_b.out" --out "$OUT/b" --first 3 --seats 2 --viewers 0 --no-record --duration 0
LABS+=("$B")

wait_trainees "$A" "lab A" "$OUT"/a/seat01-haptic.log "$OUT"/a/seat02-haptic.log
sleep 1 # a few more MeshDeltas of every seat reach the recorder

# B: a frozen server, then SIGTERM.
frozen=$(ps -o pid=,args= -s "$B" | awk '/viscera-server/ && /seat04/ { print $1 }')
[ -n "$frozen" ] || fail "no seat04 server in lab B's session"
kill -STOP "$frozen"
kill -TERM "$B"
wait_exit "$B" 30
cat "$OUT/lab_b.out"
[ "$ST" = 1 ] || fail "lab B exited with $ST, expected 1 (a server had to be killed)"
grep -q "pid $frozen still running 2 s after SIGTERM: SIGKILL" "$OUT/lab_b.out" || fail "lab B did not report the SIGKILL"
grep -q "seat04-server (pid $frozen) exited with status 137" "$OUT/lab_b.out" || fail "lab B did not name the killed server"
grep -q "seat03-server.*exited" "$OUT/lab_b.out" && fail "lab B reports the cleanly stopped seat03 server as failed"
expect_nothing_left "$B" "lab B"

# A: Ctrl-C.
kill -INT "$A"
wait_exit "$A" 30
cat "$OUT/lab_a.out"
[ "$ST" = 0 ] || fail "lab A exited with $ST after SIGINT, expected 0"
grep -q "stopped by SIGINT" "$OUT/lab_a.out" || fail "lab A did not say it was stopped by SIGINT"
expect_nothing_left "$A" "lab A"
LABS=()

DB="$OUT/a/lab.db"
expect_lab_recorded "$DB" 1 4 01 02
grep -q "^lab/seat0[34] viscera_ToolCommand" "$OUT/by_partition.txt" && fail "ToolCommands recorded in seats without trainees"
expect_recorded_pids_gone "$DB"
for s in seat01 seat02; do
  expect_frames "$OUT/a/$s-frames1"
  expect_trainee_force "$OUT/a/$s-haptic.log"
  grep -q "^haptic: path started at [0-9.]* s of the loop (--start-on-answer)" "$OUT/a/$s-haptic.log" ||
    fail "$s: the trainee did not play its path from its server's answer"
done
expect_logs "$OUT/a" recorder seat01-server seat01-viewer1 seat01-haptic seat02-server seat02-viewer1 seat02-haptic
expect_logs "$OUT/b" seat03-server seat04-server
echo PASS
