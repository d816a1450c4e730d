#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# rt_priority: --rt-priority N of viscera-server and viscera-haptic (the shared
# common/vrt.c), domain 180.
#   1. --rt-priority 0, 100 and x: exit 2 and a message naming the option and
#      the range, for both binaries;
#   2. a server --rt-priority 10 (with a checkpoint writer thread too) and a
#      scripted trainee --rt-priority 12 against it, for a few seconds. Read
#      from /proc/PID/task/*/stat while they run: when a process printed that
#      it got the priority, EXACTLY ONE of its threads, the loop's (the main
#      thread), is SCHED_FIFO at the priority and every other one (DDS's,
#      the checkpoint writer) SCHED_OTHER; when it printed the refusal warning
#      instead, no thread is FIFO. Either way the server runs its steps and
#      applies the trainee's commands;
#   3. the refusal path for sure: the same pair where the priority cannot be
#      granted (as root: CAP_SYS_NICE dropped with setpriv; otherwise a
#      priority above RLIMIT_RTPRIO): the warning text with its reason, no
#      FIFO thread, and the server still steps and the trainee still ticks.
# Under a sanitizer build the granted run must also warn that memory was not
# locked (ASan's shadow), and go on.
# usage: rt_priority_test.sh BUILD SRC OUT
set -euo pipefail
# shellcheck source=prelude.sh
source "$(dirname "$0")/prelude.sh"
SRV="$BUILD/server/viscera-server"
HAP="$BUILD/client/haptic/viscera-haptic"
SCENE="$SRC/assets/scenes/default.yaml"
TRAJ="$SRC/assets/trajectories/push_hold_kidney.traj"
SANITIZED=0
grep -q '^VISCERA_SANITIZE:BOOL=ON' "$BUILD/CMakeCache.txt" 2>/dev/null && SANITIZED=1

# 1. Invalid priorities.
for bad in 0 100 x; do
  for prog in "$SRV --scene $SCENE" "$HAP --trajectory $TRAJ"; do
    rc=0
    # shellcheck disable=SC2086
    $prog --rt-priority "$bad" > /dev/null 2> "$OUT/bad.err" || rc=$?
    [ "$rc" = 2 ] || fail "${prog%% *} --rt-priority $bad: exit $rc, expected 2"
    grep -q -- "--rt-priority '$bad' is not a SCHED_FIFO priority 1..99" "$OUT/bad.err" ||
      fail "${prog%% *} --rt-priority $bad: unclear message: $(cat "$OUT/bad.err")"
  done
done
echo "invalid priorities 0, 100, x: exit 2 with the range named (server and haptic)"

# Prints "tid policy rt_priority" per thread of a process. proc(5): field 40
# is rt_priority and 41 policy; counted after the ") " that closes the
# command name (which may hold blanks), field 3 being the first there.
threads() {
  local s rest
  for s in /proc/"$1"/task/*/stat; do
    rest=$(cat "$s" 2> /dev/null) || continue # a thread that just ended
    s=${s%/stat}
    echo "${s##*/} $(echo "${rest##*) }" | awk '{print $39, $38}')"
  done
}
# wait_line FILE REGEX SECONDS
wait_line() {
  local i
  for ((i = 0; i < $3 * 10; i++)); do
    grep -qE "$2" "$1" 2> /dev/null && return 0
    sleep 0.1
  done
  return 1
}
# check_threads PID PRIO NAME GRANTED(1/0): the thread policies as the header says.
check_threads() {
  local t
  t=$(threads "$1")
  echo "$t" > "$OUT/$3.threads"
  local n fifo other
  n=$(echo "$t" | wc -l)
  fifo=$(echo "$t" | awk '$2 == 1' | wc -l)
  other=$(echo "$t" | awk '$2 == 0' | wc -l)
  [ "$n" -ge 3 ] || fail "$3: only $n thread(s); expected the loop and DDS's threads: $t"
  if [ "$4" = 1 ]; then
    [ "$fifo" = 1 ] || fail "$3: $fifo SCHED_FIFO threads, expected exactly 1 (tid policy prio): $t"
    echo "$t" | awk -v pid="$1" -v p="$2" '$2 == 1 && $1 == pid && $3 == p {ok = 1} END {exit !ok}' ||
      fail "$3: the FIFO thread is not the loop (main) thread at priority $2: $t"
    [ "$other" = $((n - 1)) ] || fail "$3: the other threads are not all SCHED_OTHER: $t"
    echo "$3: 1 of $n threads SCHED_FIFO at $2 (the loop), $other SCHED_OTHER"
  else
    [ "$fifo" = 0 ] && [ "$other" = "$n" ] || fail "$3: refused, yet not every thread is SCHED_OTHER: $t"
    echo "$3: refused; all $n threads SCHED_OTHER"
  fi
}
# run_pair TAG SERVER_PRIO HAPTIC_PRIO [PREFIX...]: a server and a trainee
# under PREFIX (e.g. setpriv); checks the threads of both while they run and
# prints GRANTED_S and GRANTED_H (1 granted, 0 refused). Both run until the
# server has applied the trainee's press (its "ST crossed up" line) and then
# written a checkpoint (every 500 of its steps, by its own step counter):
# events, not a wall-clock time (issue 15.6); 60 s at most, a safety stop.
run_pair() {
  local tag=$1 ps=$2 ph=$3
  shift 3
  local slog="$OUT/$tag-server.log" hlog="$OUT/$tag-haptic.log"
  "$@" "$SRV" --scene "$SCENE" --rt-priority "$ps" --checkpoint "$OUT/$tag.ckpt" --checkpoint-every 0.5 \
    > "$OUT/$tag-server.out" 2> "$slog" &
  local spid=$!
  PIDS+=("$spid")
  local granted="physics loop at SCHED_FIFO priority $ps," refused="server: warning: SCHED_FIFO $ps refused \("
  wait_line "$slog" "$granted|$refused" 30 || fail "$tag: the server printed neither the grant nor the refusal"
  GRANTED_S=0
  grep -q "$granted" "$slog" && GRANTED_S=1
  "$@" "$HAP" --trajectory "$TRAJ" --duration 60 --rt-priority "$ph" \
    > "$OUT/$tag-haptic.out" 2> "$hlog" &
  local hpid=$!
  PIDS+=("$hpid")
  local hgranted="haptic: loop at SCHED_FIFO priority $ph," hrefused="haptic: warning: SCHED_FIFO $ph refused \("
  wait_line "$hlog" "$hgranted|$hrefused" 30 || fail "$tag: the trainee printed neither the grant nor the refusal"
  GRANTED_H=0
  grep -q "$hgranted" "$hlog" && GRANTED_H=1
  sleep 0.3 # its loop is running: the haptic prints the line right before it
  check_threads "$spid" "$ps" "$tag-server" "$GRANTED_S"
  check_threads "$hpid" "$ph" "$tag-haptic" "$GRANTED_H"
  wait_line "$slog" "ST crossed up" 60 || fail "$tag: the trainee's press never reached the organ"
  touch "$OUT/$tag.mark"
  for ((i = 0; i < 600; i++)); do [ "$OUT/$tag.ckpt" -nt "$OUT/$tag.mark" ] && break; sleep 0.1; done
  [ "$OUT/$tag.ckpt" -nt "$OUT/$tag.mark" ] || fail "$tag: the server wrote no checkpoint (500 steps) after the press"
  kill -INT "$hpid"
  wait "$hpid" || fail "$tag: the trainee exited $?"
  kill -INT "$spid"
  wait "$spid" || fail "$tag: the server exited $?"
  local steps ticks applied
  steps=$(sed -n 's/^SUMMARY steps=\([0-9]*\).*/\1/p' "$OUT/$tag-server.out")
  ticks=$(sed -n 's/^SUMMARY ticks=\([0-9]*\).*/\1/p' "$OUT/$tag-haptic.out")
  applied=$(sed -n 's/^server: \([0-9]*\) tool commands applied.*/\1/p' "$slog")
  # Behaviour, not speed: the server stepped (>= 500 steps, its checkpoint
  # said so), the trainee ticked, and commands were applied while both ran.
  [ "${steps:-0}" -ge 500 ] || fail "$tag: the server ran ${steps:-no} steps"
  [ "${ticks:-0}" -ge 100 ] || fail "$tag: the trainee ran ${ticks:-no} ticks"
  [ "${applied:-0}" -ge 100 ] || fail "$tag: the server applied ${applied:-no} of the trainee's commands"
  echo "$tag: server $steps steps, trainee $ticks ticks, $applied commands applied"
  if [ $SANITIZED = 1 ]; then
    for f in "$slog" "$hlog"; do
      if grep -q "at SCHED_FIFO priority" "$f"; then
        grep -q "warning: memory not fully locked (AddressSanitizer build" "$f" ||
          fail "$tag: sanitized and granted, but no warning that memory was not locked: $(cat "$f")"
      fi
    done
  fi
}

# 2. As this machine allows.
run_pair asked 10 12
echo "asked: server $([ $GRANTED_S = 1 ] && echo granted || echo refused), trainee $([ $GRANTED_H = 1 ] &&
  echo granted || echo refused)"

# 3. Refused for sure.
if [ "$(id -u)" = 0 ] && setpriv --inh-caps=-sys_nice --bounding-set=-sys_nice true 2> /dev/null; then
  PREFIX=(setpriv --inh-caps=-sys_nice --bounding-set=-sys_nice)
  PS=10 PH=12
  why="CAP_SYS_NICE dropped"
else
  lim=$(ulimit -r)
  [ "$lim" = unlimited ] && fail "cannot force a refusal: not root and RLIMIT_RTPRIO unlimited"
  [ "$lim" -ge 99 ] && fail "cannot force a refusal: not root and RLIMIT_RTPRIO $lim"
  PREFIX=(env)
  PS=$((lim + 1)) PH=$((lim + 1))
  why="priority $PS above RLIMIT_RTPRIO $lim"
fi
run_pair refused "$PS" "$PH" "${PREFIX[@]}"
[ $GRANTED_S = 0 ] && [ $GRANTED_H = 0 ] || fail "refused run ($why): a priority was granted"
for f in "$OUT/refused-server.log" "$OUT/refused-haptic.log"; do
  grep -qE "warning: SCHED_FIFO [0-9]+ refused \(Operation not permitted: needs root, CAP_SYS_NICE or an RLIMIT_RTPRIO.*\); running at normal priority" "$f" ||
    fail "refused run ($why): the warning does not name the reason: $(grep warning "$f")"
done
echo "refused ($why): warnings name the reason, both ran at normal priority"
echo "PASS"
