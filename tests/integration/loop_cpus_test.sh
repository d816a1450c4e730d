#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# loop_cpus: where the 1 kHz loops run. --cpu-wake-latency US of
# viscera-server and viscera-haptic (the shared common/cpu_wake.c: a PM QoS
# request on /dev/cpu_dma_latency held while the program runs) and
# viscera-server --physics-cpus LIST (common/cpu_pin.c), domain 175.
#   1. --cpu-wake-latency -1, 10001 and x: exit 2 and a message naming the
#      option and the range, for both binaries;
#   2. a server and a scripted trainee, both --cpu-wake-latency 0, for a few
#      seconds. When the server printed that it holds the request: while it
#      runs no CPU enters an idle state deeper than polling (the kernel's own
#      counters, /sys/devices/system/cpu/cpu*/cpuidle/state[1-9]*/usage, do
#      not move: a request of 0 us leaves only the polling state) and the
#      server has the device open. When it printed the refusal instead (no write access), the
#      warning names the device and the reason. Either way the server steps
#      and applies the trainee's commands;
#   3. the refusal path for sure, as root: the same pair as user nobody
#      (setpriv): the warning with "Permission denied", and the session runs
#      (skipped when nobody cannot reach the build or the scene, e.g. a clone
#      under /root);
#   4. --physics-cpus: bad lists exit 2 naming what is wrong; on a machine of
#      two or more CPUs, two seats on one physics thread kept on the last CPU:
#      that thread (one of those named 'seats01-02') may run on that CPU only,
#      the DDS receive thread keeps the process's CPUs, and both seats step.
# usage: loop_cpus_test.sh BUILD SRC OUT
set -euo pipefail
# shellcheck source=prelude.sh
source "$(dirname "$0")/prelude.sh"
SRV="$BUILD/server/viscera-server"
HAP="$BUILD/client/haptic/viscera-haptic"
SCENE="$SRC/assets/scenes/default.yaml"
TRAJ="$SRC/assets/trajectories/push_hold_kidney.traj"
DEV=/dev/cpu_dma_latency

# 1. Invalid bounds.
for bad in -1 10001 x; do
  for prog in "$SRV --scene $SCENE" "$HAP --trajectory $TRAJ"; do
    rc=0
    # shellcheck disable=SC2086
    $prog --cpu-wake-latency "$bad" > /dev/null 2> "$OUT/bad.err" || rc=$?
    [ "$rc" = 2 ] || fail "${prog%% *} --cpu-wake-latency $bad: exit $rc, expected 2"
    grep -q -- "--cpu-wake-latency '$bad' is not a number of microseconds 0..10000" "$OUT/bad.err" ||
      fail "${prog%% *} --cpu-wake-latency $bad: unclear message: $(cat "$OUT/bad.err")"
  done
done

# Idle entries deeper than polling, summed over every CPU ("" without cpuidle).
deep_idle() {
  local f s=0 any=0
  for f in /sys/devices/system/cpu/cpu[0-9]*/cpuidle/state[1-9]*/usage; do
    [ -r "$f" ] || continue
    s=$((s + $(cat "$f"))); any=1
  done
  [ $any = 1 ] && echo $s || true
}
# holders: pids of ours that have the device open
holders() {
  local p fd
  for p in "$@"; do
    for fd in /proc/"$p"/fd/*; do
      [ "$(readlink "$fd" 2>/dev/null)" = "$DEV" ] && { echo "$p"; break; }
    done
  done
  return 0
}

# session TAG [RUNAS...]: server + trainee with --cpu-wake-latency 0; sets SRV_PID, HAP_PID
session() {
  local tag=$1; shift
  "$@" "$SRV" --scene "$SCENE" --partition "cpuwake/$tag" --duration 6 --cpu-wake-latency 0 \
    > "$OUT/$tag-server.out" 2> "$OUT/$tag-server.log" & SRV_PID=$!; PIDS+=("$SRV_PID")
  "$@" "$HAP" --partition "cpuwake/$tag" --trajectory "$TRAJ" --duration 4 --cpu-wake-latency 0 \
    > "$OUT/$tag-haptic.out" 2> "$OUT/$tag-haptic.log" & HAP_PID=$!; PIDS+=("$HAP_PID")
  for _ in $(seq 1 100); do grep -q "running on domain\|refused" "$OUT/$tag-server.log" && break; sleep 0.1; done
}
# ran TAG: the server stepped and applied the trainee's commands
ran() {
  wait "$SRV_PID" || fail "$1: the server failed"
  wait "$HAP_PID" || fail "$1: the trainee failed"
  local applied
  applied=$(sed -n 's/^server: \([0-9]*\) tool commands applied.*/\1/p' "$OUT/$1-server.log")
  [ "${applied:-0}" -gt 1000 ] || fail "$1: the server applied ${applied:-no} commands of the trainee"
}

# 2. Held (or refused, when this user cannot write the device).
session held
if grep -q "server: CPU wake-up latency held at <= 0 us" "$OUT/held-server.log"; then
  sleep 1
  [ -n "$(holders "$SRV_PID")" ] || fail "the server says it holds the request but does not have $DEV open"
  d0=$(deep_idle)
  if [ -n "$d0" ]; then
    sleep 1.5
    d1=$(deep_idle)
    [ "$d1" = "$d0" ] || fail "CPUs went $((d1 - d0)) times into a deeper idle state than polling while the request was held"
    echo "held: no deep idle entry in 1.5 s"
  else
    echo "held (this kernel has no cpuidle states to check)"
  fi
  grep -q "haptic: CPU wake-up latency held at <= 0 us" "$OUT/held-haptic.log" ||
    fail "the trainee did not say it holds the request: $(cat "$OUT/held-haptic.log")"
  ran held
else
  grep -q "server: warning: --cpu-wake-latency 0 refused: $DEV: " "$OUT/held-server.log" ||
    fail "the server neither holds the request nor says why not: $(cat "$OUT/held-server.log")"
  ran held
  echo "refused for this user: $(grep -m1 refused "$OUT/held-server.log")"
fi

# 3. Refused for sure: as nobody, when we are root.
AS_NOBODY=(setpriv --reuid=65534 --regid=65534 --clear-groups)
if [ "$(id -u)" != 0 ] || ! command -v setpriv > /dev/null; then
  echo "part 3 skipped: not root, or no setpriv"
elif ! "${AS_NOBODY[@]}" sh -c '[ -x "$1" ] && [ -x "$2" ] && [ -r "$3" ] && [ -r "$4" ] && [ -r "$5" ]' sh "$SRV" "$HAP" "$SCENE" "$TRAJ" "${CYCLONEDDS_URI#file://}"; then
  echo "part 3 skipped: user nobody cannot reach the build or the scene from here"
else
  session nobody "${AS_NOBODY[@]}"
  for who in server haptic; do
    grep -q "$who: warning: --cpu-wake-latency 0 refused: $DEV: Permission denied" "$OUT/nobody-$who.log" ||
      fail "as nobody, the $who did not name the refusal: $(cat "$OUT/nobody-$who.log")"
  done
  ran nobody
  echo "refused as nobody, the session ran"
fi

# 4. The physics loop kept on a CPU.
for bad in x 1- 3-1 "0,,1" 999 "$(nproc --all)"; do
  rc=0
  "$SRV" --scene "$SCENE" --physics-cpus "$bad" > /dev/null 2> "$OUT/badcpu.err" || rc=$?
  [ "$rc" = 2 ] && grep -q -- "--physics-cpus: .*'$bad'" "$OUT/badcpu.err" ||
    fail "--physics-cpus '$bad': exit $rc, expected 2 naming it: $(cat "$OUT/badcpu.err")"
done
echo "bad CPU lists exit 2 naming them"
# allowed TID-DIR: the CPUs the thread may run on (/proc status)
allowed() { sed -n 's/^Cpus_allowed_list:[[:space:]]*//p' "$1/status"; }
if [ "$(nproc)" -ge 2 ]; then
  last=$(($(nproc --all) - 1))
  "$SRV" --scene "$SCENE" --partition cpuwake/pin --seats 2 --seat-threads 1 --physics-cpus "$last" --duration 4 \
    > "$OUT/pin-server.out" 2> "$OUT/pin-server.log" & PIN=$!; PIDS+=("$PIN")
  for _ in $(seq 1 100); do grep -q "physics loop kept on CPUs $last" "$OUT/pin-server.log" && break; sleep 0.1; done
  grep -q "physics loop kept on CPUs $last" "$OUT/pin-server.log" ||
    fail "the server did not say it keeps the physics loop on CPU $last: $(cat "$OUT/pin-server.log")"
  sleep 0.5
  phys="" recv=""
  for t in /proc/"$PIN"/task/*; do
    case "$(cat "$t/comm" 2> /dev/null)" in
      # (threads the group thread started, its outbox drain among them, inherit
      # its name but not its CPUs: they were started before it pinned itself)
      seats01-02) [ "$(allowed "$t")" = "$last" ] && phys=ok || [ "$phys" = ok ] || phys="$(allowed "$t")" ;;
      recv*) recv="$(allowed "$t")" ;;
    esac
  done
  [ "$phys" = ok ] || fail "the physics thread 'seats01-02' may run on CPUs '${phys:-(no such thread)}', not $last only"
  [ -n "$recv" ] && [ "$recv" != "$last" ] || fail "the DDS receive thread was pinned too (CPUs '$recv')"
  wait "$PIN" || fail "the pinned server failed"
  steps=$(sed -n 's/^SUMMARY steps=\([0-9]*\).*/\1/p' "$OUT/pin-server.out" | sort -n | head -1)
  [ "${steps:-0}" -ge 1000 ] || fail "a pinned seat took ${steps:-no} steps"
  echo "physics thread on CPU $last only, DDS receive thread on $recv; both seats stepped (>= $steps steps)"
else
  echo "part 4 (pinning) skipped: one CPU"
fi
echo PASS
