#!/usr/bin/env bash
# Real-time loops (vrt.h): `viscera-server --rt-priority N` makes exactly
# its physics loop thread SCHED_FIFO at N (DDS and checkpoint threads stay
# normal), `viscera-haptic --rt-priority N` exactly its tick thread; without
# the privilege (CAP_SYS_NICE dropped with setpriv) both warn, name the
# reason and run on at normal priority; bad values exit 2 naming the option.
set -euo pipefail
# shellcheck source=prelude.sh
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
SCENE="$SRC/assets/scenes/default.yaml"
# "name policy priority" per thread of PID (policy 1 = SCHED_FIFO, 0 = normal;
# /proc/PID/task/TID/stat fields 41 and 40, counted after the command name).
threads() {
  local t
  for t in /proc/"$1"/task/*; do
    echo "$(cat "$t/comm" 2>/dev/null) $(sed 's/.*) //' "$t/stat" 2>/dev/null | awk '{ print $39, $38 }')"
  done
}
fifo_threads() { threads "$1" | awk -v p="$2" '$2 == 1 && $3 == p' | wc -l; }
other_threads() { threads "$1" | awk '$2 != 1' | wc -l; }
for bad in 0 100 x 5.5; do
  set +e; "$BUILD/server/viscera-server" --scene "$SCENE" --rt-priority "$bad" > /dev/null 2> "$OUT/bad.err"; rc=$?; set -e
  [ $rc = 2 ] && grep -q -- "--rt-priority '$bad' must be 1..99" "$OUT/bad.err" || fail "server --rt-priority $bad: exit $rc, $(cat "$OUT/bad.err")"
  set +e; "$BUILD/client/haptic/viscera-haptic" --rt-priority "$bad" --duration 0.1 > /dev/null 2> "$OUT/bad.err"; rc=$?; set -e
  [ $rc = 2 ] || fail "haptic --rt-priority $bad: exit $rc"
done
"$BUILD/server/viscera-server" --scene "$SCENE" --partition rt/seat --rt-priority 10 --duration 5 \
  --checkpoint "$OUT/seat.ckpt" > "$OUT/server.out" 2> "$OUT/server.log" &
srv=$!; PIDS+=("$srv")
sleep 1
printf '%s\n' "0 0.012 0.004 0.07" "3 0.012 0.004 0.06" > "$OUT/hover.traj"
"$BUILD/client/haptic/viscera-haptic" --partition rt/seat --trajectory "$OUT/hover.traj" --duration 3 --rt-priority 12 \
  > "$OUT/haptic.out" 2> "$OUT/haptic.log" &
hap=$!; PIDS+=("$hap")
sleep 1.5
threads "$srv" > "$OUT/server.threads"; threads "$hap" > "$OUT/haptic.threads"
wait "$hap" || fail "haptic client failed"
wait "$srv" || fail "server failed"
echo "server threads:"; cat "$OUT/server.threads"; echo "haptic threads:"; cat "$OUT/haptic.threads"
check_proc() { # name log threads-file priority
  if grep -q "loop at SCHED_FIFO priority $4" "$2"; then
    n=$(awk -v p="$4" '$2 == 1 && $3 == p' "$3" | wc -l); o=$(awk '$2 != 1' "$3" | wc -l)
    [ "$n" = 1 ] || fail "$1: $n threads at SCHED_FIFO $4 (expected exactly the loop thread)"
    [ "$o" -ge 3 ] || fail "$1: only $o threads at normal priority (the DDS threads must stay normal)"
  else
    # Unprivileged CI: the refusal path (also checked below with setpriv).
    grep -q "warning: SCHED_FIFO $4 refused" "$2" || fail "$1: neither real-time nor a refusal warning"
  fi
}
check_proc server "$OUT/server.log" "$OUT/server.threads" 10
check_proc haptic "$OUT/haptic.log" "$OUT/haptic.threads" 12
grep -q "^server: [0-9]* steps" "$OUT/server.log" || fail "the real-time server did not report its steps"
grep -q "^SUMMARY ticks=" "$OUT/haptic.out" "$OUT/haptic.log" 2>/dev/null || fail "the real-time haptic client did not report"
# Without CAP_SYS_NICE: a warning naming the reason, and the loop runs on.
if setpriv --bounding-set=-sys_nice --inh-caps=-sys_nice true 2>/dev/null; then
  setpriv --bounding-set=-sys_nice --inh-caps=-sys_nice "$BUILD/server/viscera-server" --scene "$SCENE" \
    --partition rt/nopriv --rt-priority 10 --duration 1 > /dev/null 2> "$OUT/nopriv.log" || fail "unprivileged server failed"
  grep -q "server: warning: SCHED_FIFO 10 refused (Operation not permitted); running at normal priority" \
    "$OUT/nopriv.log" || fail "unprivileged server: no refusal warning"
  steps=$(sed -n 's/^server: \([0-9]*\) steps.*/\1/p' "$OUT/nopriv.log")
  [ "${steps:-0}" -ge 500 ] || fail "unprivileged server ran ${steps:-0} steps in 1 s"
  echo "refusal: $(grep refused "$OUT/nopriv.log"); $steps steps"
fi
echo "PASS"
