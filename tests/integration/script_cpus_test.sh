#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# script_cpus: the deploy scripts hand the loop placement options on to the
# processes they start (issue 17 item 6), domain 176. What the programs do
# with them is loop_cpus's; this test checks that the scripts pass them:
#   1. bad values exit 2 with a message naming the option: lab.sh and
#      load_bench.sh --cpu-wake-latency x / 10001, load_bench.sh
#      --server-cpus / --client-cpus / --physics-cpus with lists this
#      machine cannot run on;
#   2. lab.sh --cpu-wake-latency 0 (one seat, a trainee, no viewer): the
#      seat's server and its trainee each say they hold the request or why
#      not (the option reached both);
#   3. load_bench.sh --one-server --seats 2 --seat-threads 1 --cpu-wake-latency 0
#      --server-cpus 0 --physics-cpus LAST --client-cpus 0 (LAST: the last
#      CPU, 0 on a one-CPU machine): while the lab runs, the server and
#      every trainee and subscriber may run on CPU 0 only (/proc status of
#      each process the benchmark registered), the server's physics thread
#      ('seats01-02') on LAST only; every server and trainee, alone and in
#      the lab, holds the request or says why not; the summary states the
#      wake-up request, the refusals it counted (none when the logs name
#      none) and the placement.
# usage: script_cpus_test.sh BUILD SRC OUT
set -euo pipefail
# shellcheck source=prelude.sh
source "$(dirname "$0")/prelude.sh"
LAB="$SRC/deploy/lab.sh"
BENCH="$SRC/deploy/load_bench.sh"
[ -x "$BUILD/tests/bench/delta_sub" ] || { echo "skipped: no benchmarks in this build (delta_sub)"; exit 77; }

# expect_exit2 WHAT PATTERN CMD...: CMD exits 2 and its message matches PATTERN
expect_exit2() {
  local what=$1 pat=$2 rc=0; shift 2
  "$@" > "$OUT/bad.out" 2> "$OUT/bad.err" || rc=$?
  [ "$rc" = 2 ] || fail "$what: exit $rc, expected 2"
  grep -Eq -- "$pat" "$OUT/bad.err" || fail "$what: unclear message: $(cat "$OUT/bad.err")"
}
# 1. Bad values.
for bad in x 10001; do
  expect_exit2 "lab.sh --cpu-wake-latency $bad" "lab.sh: --cpu-wake-latency must be a number of microseconds 0..10000" \
    bash "$LAB" --build "$BUILD" --out "$OUT/badlab" --cpu-wake-latency "$bad"
  expect_exit2 "load_bench.sh --cpu-wake-latency $bad" "--cpu-wake-latency '$bad' is not a number of microseconds 0..10000" \
    bash "$BENCH" --build "$BUILD" --out "$OUT/badbench" --cpu-wake-latency "$bad"
done
for kind in server client physics; do
  for bad in x 1- "$(nproc --all)"; do
    expect_exit2 "load_bench.sh --$kind-cpus $bad" "--$kind-cpus '$bad' is not a CPU list of this machine" \
      bash "$BENCH" --build "$BUILD" --out "$OUT/badbench" --"$kind"-cpus "$bad"
  done
done
[ ! -e "$OUT/badbench" ] || fail "load_bench.sh started (made its output directory) with a bad option"
echo "bad values exit 2 naming the option"

# holds_or_says LOG WHO: the program held the wake-up request or said why not
holds_or_says() {
  grep -Eq "^$2: (CPU wake-up latency held at <= 0 us|warning: --cpu-wake-latency 0 refused: /dev/cpu_dma_latency: )" "$1" ||
    fail "$(basename "$1"): no word of --cpu-wake-latency 0 (the option did not reach the $2): $(tail -5 "$1")"
}

# 2. lab.sh: one seat and its trainee.
rc=0
timeout 60 bash "$LAB" --build "$BUILD" --out "$OUT/lab" --prefix scpu --seats 1 --trainees --viewers 0 --no-record \
  --duration 4 --cpu-wake-latency 0 > "$OUT/lab.out" 2>&1 || rc=$?
[ "$rc" = 0 ] || { cat "$OUT/lab.out" >&2; fail "lab.sh --cpu-wake-latency 0 exited $rc"; }
holds_or_says "$OUT/lab/seat01-server.log" server
holds_or_says "$OUT/lab/seat01-haptic.log" haptic
echo "lab.sh: $(grep -Eho '^server: (CPU wake-up latency held at <= 0 us|warning: --cpu-wake-latency 0 refused)' "$OUT/lab/seat01-server.log")"

# 3. load_bench.sh: placement and wake-up request for every process.
last=$(($(nproc) >= 2 ? $(nproc --all) - 1 : 0))
B="$OUT/bench"
bash "$BENCH" --build "$BUILD" --out "$B" --seats 2 --subscribers 2 --duration 8 --baseline 2 --one-server \
  --seat-threads 1 --rt-priority 0 --haptic-rt-priority 0 --cpu-wake-latency 0 --server-cpus 0 \
  --physics-cpus "$last" --client-cpus 0 > "$OUT/bench.out" 2>&1 & BP=$!
PIDS+=("$BP")
# allowed PATH: the CPUs the process or thread (/proc/PID, /proc/PID/task/TID)
# may run on ("" when it is gone)
allowed() { sed -n 's/^Cpus_allowed_list:[[:space:]]*//p' "$1"/status 2> /dev/null || true; }
# The lab's processes, once the trainees and the early subscriber are registered.
for _ in $(seq 1 300); do
  [ "$(grep -c ' trainee \| subscriber ' "$B/procs.txt" 2> /dev/null || true)" -ge 3 ] && break
  kill -0 "$BP" 2> /dev/null || break
  sleep 0.1
done
seen=0 phys=""
while read -r pid kind name _; do
  a=$(allowed /proc/"$pid")
  [ -n "$a" ] || continue # already ended
  [ "$a" = 0 ] || fail "load_bench.sh: the $kind $name (pid $pid) may run on CPUs '$a', expected '0'"
  seen=$((seen + 1))
  [ "$kind" = server ] || continue
  for t in /proc/"$pid"/task/*; do
    # (threads the physics thread started before it pinned itself share its
    # name but not its CPUs: one of that name on LAST is the loop)
    [ "$(cat "$t/comm" 2> /dev/null)" = seats01-02 ] || continue
    [ "$(allowed "$t")" = "$last" ] && phys=ok || [ "$phys" = ok ] || phys="$(allowed "$t")"
  done
done < <(cat "$B/procs.txt" 2> /dev/null || true)
[ "$seen" -ge 4 ] || fail "load_bench.sh: only $seen of its lab's processes seen running: $(cat "$B/procs.txt" 2> /dev/null)"
[ "$phys" = ok ] || fail "load_bench.sh: the server's physics thread 'seats01-02' may run on CPUs '$phys', expected '$last'"
rc=0
wait "$BP" || rc=$?
[ "$rc" = 0 ] || { tail -20 "$OUT/bench.out" >&2; fail "load_bench.sh exited $rc"; }
echo "load_bench.sh: $seen processes on CPU 0, the physics thread on CPU $last"
logs=0 refused=0
for f in "$B"/alone-server.log "$B"/alone2-server.log "$B"/seats-server.log; do
  holds_or_says "$f" server; logs=$((logs + 1))
  grep -q 'cpu-wake-latency 0 refused' "$f" && refused=$((refused + 1))
done
for f in "$B"/alone-haptic.log "$B"/alone2-haptic.log "$B"/seat01-haptic.log "$B"/seat02-haptic.log; do
  holds_or_says "$f" haptic; logs=$((logs + 1))
  grep -q 'cpu-wake-latency 0 refused' "$f" && refused=$((refused + 1))
done
S="$B/summary.txt"
# (The summary counts the per-seat split of the server's log as well.)
grep -Eq "^  CPU wake-up latency <= 0 us \(PM QoS\), alone and in the lab: refused by [0-9]+ of [0-9]+ processes$" "$S" ||
  fail "the summary does not state the wake-up request: $(cat "$S")"
if [ "$refused" = 0 ]; then want="refused by 0 of"; else want="refused by [1-9][0-9]* of"; fi
grep -q "$want" "$S" || fail "the summary's refusals do not match the logs' ($refused of $logs): $(grep 'wake-up' "$S")"
grep -qx "  CPUs: servers on 0 (their physics loops on $last), trainees and subscribers on 0" "$S" ||
  fail "the summary does not state the placement: $(grep 'CPUs' "$S" || cat "$S")"
grep -Eq '^  seat0[12]: [0-9]{4,} steps' "$S" || fail "the lab's seats did not step: $(cat "$S")"
echo "load_bench.sh: every server and trainee got the request ($refused of $logs refused); the summary states it and the placement"
