#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Classroom load benchmark (issue 7): SEATS servers (assets/scenes/
# classroom_kidney.yaml, meshes at 60 Hz, or --scene FILE) with a scripted
# trainee each pressing and releasing for the whole run (--busy: pressing
# and sweeping without ever letting go, so no organ ever rests or sleeps:
# the worst case of a classroom), SUBSCRIBERS light viewers
# (tests/bench/delta_sub: keyframe + every MeshDelta, latency measured) spread
# over the seats, a third of them joining late (at a third of the run).
# Samples every server's CPU time and resident memory every 10 s, and the CPU
# time of every process it started (servers, trainees, subscribers) every
# second; at the end prints per-seat step time (median, p99; wall time and the
# server thread's CPU time, which tells the step's own cost from time spent
# preempted by the other processes) and real-time ratio, delta latency
# (median, p99 over all subscribers), the time late joiners waited for their
# keyframe, CPU / memory at the start and the end of the run, each trainee's
# loop rate, late ticks and command->feedback latency, and the CPU the
# processes of each kind used (% of one core: the machine's total demand).
# Writes OUT/load.csv (server samples), OUT/cpu.csv (every process, every
# second) and OUT/summary.txt.
#
# --one-server: the seats run as threads of one viscera-server process
# (--seats N: partitions load/seat01..) instead of one process each; its
# log is split per seat afterwards, so the figures read the same.
# --seat-threads K (with --one-server): the process steps its seats on K
# physics threads, each stepping its seats one after the other every tick
# (viscera-server --seat-threads; server/session/seat_group.h); default the
# server's own, one per online CPU; K = SEATS: a thread per seat.
#
# --beside (with --one-server, 2 seats or more): the lab's last seat runs in
# a server process of its own, exactly as the seat alone runs, while the
# other seats run in the one process: five seats are still on the machine
# with all their clients, and the seat beside is a seat alone under the
# lab's load. The summary sets the one process's seats against the seat
# alone (as always), the seat beside against the seat alone (what the
# machine shared with the lab costs any seat), and the one process's seats
# against the seat beside (what stepping seats together costs or saves
# under the same load; docs/numerics.md §11.9).
#
# --cpu-wake-latency US: the servers and trainees (alone and in the lab)
# hold a PM QoS request that no CPU take longer than US us to wake from
# idle (viscera-server --cpu-wake-latency; 0: idle CPUs poll): on a virtual
# machine each sleep otherwise hands the core to the host and the step
# after it pays (docs/numerics.md §11.5).
#
# --server-cpus LIST / --client-cpus LIST (taskset CPU lists): the servers,
# and the trainees and subscribers, alone and in the lab, run on those CPUs
# only; --physics-cpus LIST then keeps the servers' physics loops alone on
# their CPUs (viscera-server --physics-cpus), their DDS threads staying on
# --server-cpus. On one machine the clients otherwise share the physics threads'
# cores, which a classroom's clients, at their own stations, do not: a
# ContactFeedback written on loopback wakes its trainee's receive thread on
# the writer's CPU, where it preempts the physics thread
# (docs/numerics.md §11.5).
#
# --command-playout N: every server (alone and in the lab) puts its tools'
# commands into effect one per step, holding up to N steps of them
# (viscera-server --command-playout; server/session/command_playout.h): a
# trainee whose commands arrive unevenly then still drives an even tool
# path; the summary sums what the servers say they held back and dropped.
#
# Scheduling: the servers' physics loops run SCHED_FIFO at --rt-priority S
# (default 70) and the trainees' 1 kHz loops at --haptic-rt-priority H
# (default 80: the haptic tick is the most latency-critical thread and is
# short); only those threads, DDS threads stay normal; 0 = normal scheduling.
# Without root or CAP_SYS_NICE the processes warn and run at normal priority
# (the summary says how many were refused).
#
# The scene's kidney sleeps while its trainee is away (physics.sleep_speed,
# assets/scenes/README.md): the summary gives, next to the step times of all
# steps, those of the steps that stepped the organ (the physics work) and the
# share of steps in which it slept.
#
# Before the lab starts, one seat runs alone (same scene, same trainee, same
# scheduling, its share of the subscribers: SUBSCRIBERS / SEATS rounded up) for
# BASELINE s: its step times are the reference that "step time unchanged" is
# judged against (with no subscriber the seat alone would skip the mesh
# writes a lab seat makes for its readers).
# The seats' step CPU medians are compared with it as a whole and in the two
# parts the server's log splits them into (its "step CPU split" line: the
# tissue step, and the rest: commands, feedback, inputs, frames). The seat
# alone runs again after the lab: the two runs' difference is the
# reference's own spread, and a line says "unchanged within noise" when
# every seat's median lies within the two runs' span widened on each side by
# their difference, "slower than the seat alone beyond noise" when one lies
# above it, "no slower ... (faster beyond noise)" when one lies below it.
#
# --rounds R: the whole (seat alone, lab, seat alone again) R times, each
# round in OUT/roundK/ with its own summary; OUT/summary.txt then sets each
# round's seats against that round's two runs of the seat alone and judges
# the median over the rounds against the median of the rounds' own
# alone-to-alone spread (the same band as one run's, see above). On a
# virtual machine the seat alone's step drifts by a fifth over minutes
# (docs/numerics.md §11.5): rounds taken one after the other see the lab and
# its reference under the same drift, where one run's two references may
# not.
#
# usage: deploy/load_bench.sh [--build DIR] [--out DIR] [--seats N] [--subscribers M] [--duration S]
#                             [--baseline S] [--rt-priority S] [--haptic-rt-priority H]
#                             [--scene FILE] [--busy] [--one-server [--seat-threads K]]
#                             [--cpu-wake-latency US] [--server-cpus LIST] [--client-cpus LIST]
#                             [--physics-cpus LIST] [--command-playout N] [--rounds R] [--beside]
# (the press is at x 12 mm, y 4 mm from above, 8 mm deep into an organ whose
# top is at z = 35 mm: the shipped kidney and gallbladder; classroom
# scenes: classroom_kidney.yaml, classroom_gallbladder.yaml)
# defaults: build/, out/load, 5 seats, 30 subscribers, 600 s (the issue's setting), baseline 30 s,
#           servers SCHED_FIFO 70, trainees SCHED_FIFO 80
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build" OUT="$ROOT/out/load" SEATS=5 SUBS=30 DURATION=600 BASELINE=30 RTPRIO=70 HRTPRIO=80
SCENE="$ROOT/assets/scenes/classroom_kidney.yaml" BUSY=0 ONE=0 SEATTH=0 WAKE="" SRVCPUS="" CLICPUS="" PHYCPUS=""
PLAYOUT="" BESIDE=0
ROUNDS=1 ROUND_ARGS=() # every option but --out and --rounds, for each round's own run
while [ $# -gt 0 ]; do
  case "$1" in
    --out | --rounds) ;;
    --busy | --one-server | --beside) ROUND_ARGS+=("$1") ;;
    *) ROUND_ARGS+=("$1" "${2-}") ;;
  esac
  case "$1" in
    --build) BUILD="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --seats) SEATS="$2"; shift 2 ;;
    --subscribers) SUBS="$2"; shift 2 ;;
    --duration) DURATION="$2"; shift 2 ;;
    --baseline) BASELINE="$2"; shift 2 ;;
    --rt-priority) RTPRIO="$2"; shift 2 ;;
    --haptic-rt-priority) HRTPRIO="$2"; shift 2 ;;
    --scene) SCENE="$2"; shift 2 ;;
    --busy) BUSY=1; shift ;;
    --one-server) ONE=1; shift ;;
    --beside) BESIDE=1; shift ;;
    --seat-threads) SEATTH="$2"; shift 2 ;;
    --cpu-wake-latency) WAKE="$2"; shift 2 ;;
    --server-cpus) SRVCPUS="$2"; shift 2 ;;
    --physics-cpus) PHYCPUS="$2"; shift 2 ;;
    --client-cpus) CLICPUS="$2"; shift 2 ;;
    --rounds) ROUNDS="$2"; shift 2 ;;
    --command-playout) PLAYOUT="$2"; shift 2 ;;
    -h|--help) awk 'NR > 2 && /^#/ { sub(/^# ?/, ""); print; next } NR > 2 { exit }' "$0"; exit 0 ;;
    *) echo "load_bench.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
for v in SEATS SUBS DURATION BASELINE ROUNDS; do [[ "${!v}" =~ ^[0-9]+$ ]] && [ "${!v}" -ge 1 ] || { echo "load_bench.sh: bad ${v,,}" >&2; exit 2; }; done
[ "$BESIDE" = 0 ] || { [ "$ONE" = 1 ] && [ "$SEATS" -ge 2 ]; } ||
  { echo "load_bench.sh: --beside needs --one-server and 2 seats or more (the last seat runs in a process of its own)" >&2; exit 2; }
GROUPED=$((SEATS - BESIDE)) # the seats the lab's one server process steps (--one-server)
[[ "$SEATTH" =~ ^[0-9]+$ ]] && [ "$SEATTH" -le "$GROUPED" ] ||
  { echo "load_bench.sh: --seat-threads '$SEATTH' is not a number of threads 1..$GROUPED" >&2; exit 2; }
SEATTH=$((10#$SEATTH))
[ "$SEATTH" = 0 ] || [ "$ONE" = 1 ] || { echo "load_bench.sh: --seat-threads needs --one-server" >&2; exit 2; }
GROUPS_OPT=() NTHREADS=$SEATTH
[ "$SEATTH" -gt 0 ] && GROUPS_OPT=(--seat-threads "$SEATTH")
[ "$NTHREADS" -gt 0 ] || NTHREADS=$(( $(nproc) < GROUPED ? $(nproc) : GROUPED )) # the server's default
# The seats set against the seat alone: with --beside all but the last.
LAB_SEATS=$(seq 1 "$GROUPED")
BESIDE_SEAT=$(printf 'seat%02d' "$SEATS")
check_prio() {
  [[ "$2" =~ ^[0-9]{1,2}$ ]] ||
    { echo "load_bench.sh: $1 '$2' is not 0 (normal scheduling) or a SCHED_FIFO priority 1..99" >&2; exit 2; }
}
check_prio --rt-priority "$RTPRIO"; check_prio --haptic-rt-priority "$HRTPRIO"
RTPRIO=$((10#$RTPRIO)) HRTPRIO=$((10#$HRTPRIO))
# The options each server and trainee gets (none for 0: normal scheduling).
SRV_RT=() HAP_RT=()
[ "$RTPRIO" -gt 0 ] && SRV_RT=(--rt-priority "$RTPRIO")
[ "$HRTPRIO" -gt 0 ] && HAP_RT=(--rt-priority "$HRTPRIO")
if [ -n "$WAKE" ]; then
  [[ "$WAKE" =~ ^[0-9]{1,5}$ ]] && [ "$((10#$WAKE))" -le 10000 ] ||
    { echo "load_bench.sh: --cpu-wake-latency '$WAKE' is not a number of microseconds 0..10000" >&2; exit 2; }
  WAKE=$((10#$WAKE))
  SRV_RT+=(--cpu-wake-latency "$WAKE") HAP_RT+=(--cpu-wake-latency "$WAKE")
fi
# CPU placement (taskset): servers on --server-cpus, trainees and subscribers
# on --client-cpus (alone and in the lab); none given: the scheduler's.
SRV_PIN=() CLI_PIN=()
for v in server:"$SRVCPUS" client:"$CLICPUS" physics:"$PHYCPUS"; do
  l=${v#*:}
  [ -z "$l" ] && continue
  [[ "$l" =~ ^[0-9]+([,-][0-9]+)*$ ]] && taskset -c "$l" true 2>/dev/null ||
    { echo "load_bench.sh: --${v%%:*}-cpus '$l' is not a CPU list of this machine (taskset -c)" >&2; exit 2; }
done
[ -n "$SRVCPUS" ] && SRV_PIN=(taskset -c "$SRVCPUS")
[ -n "$CLICPUS" ] && CLI_PIN=(taskset -c "$CLICPUS")
[ -n "$PHYCPUS" ] && SRV_RT+=(--physics-cpus "$PHYCPUS")
if [ -n "$PLAYOUT" ]; then
  [[ "$PLAYOUT" =~ ^[0-8]$ ]] || { echo "load_bench.sh: --command-playout '$PLAYOUT' is not a number of steps 0..8" >&2; exit 2; }
  SRV_RT+=(--command-playout "$PLAYOUT")
fi
[ -x "$BUILD/tests/bench/delta_sub" ] || { echo "load_bench.sh: $BUILD/tests/bench/delta_sub missing (build with -DVISCERA_BUILD_BENCH=ON)" >&2; exit 1; }
export CYCLONEDDS_URI="${CYCLONEDDS_URI:-file://$ROOT/deploy/cyclonedds-loopback.xml}"
# Another configuration than loopback: with a security fragment, or VISCERA_INSECURE=1 (warns).
# shellcheck source=net_guard.sh
source "$ROOT/deploy/net_guard.sh"
# shellcheck source=seat_logs.sh
source "$ROOT/deploy/seat_logs.sh"
net_guard load_bench.sh "$CYCLONEDDS_URI" 0 "${VISCERA_INSECURE:-0}" \
  "add an identity fragment from deploy/pki.sh to it, or set VISCERA_INSECURE=1 to run without DDS Security" || exit 2
export VISCERA_DOMAIN="${VISCERA_DOMAIN:-0}"
[ -r "$SCENE" ] || { echo "load_bench.sh: cannot read the scene '$SCENE'" >&2; exit 2; }
SCENE_NAME=$(basename "$SCENE" .yaml)
# The medians a server log gives: the whole step's CPU time, and its two
# parts (the server's "step CPU split" line: the runtime's tissue step, and
# the rest: commands, feedback, inputs, frames).
STEP_SED='s/^server: step CPU time median \([0-9.]*\) us.*/\1/p'
TISSUE_SED='s/^server: step CPU split: tissue (contact and organs) median \([0-9.]*\) us.*/\1/p'
REST_SED='s/^server: step CPU split: .* the rest ([^)]*) median \([0-9.]*\) us.*/\1/p'
# The physics work behind the tissue step (the server's "physics work" line:
# node updates per step with an organ awake, and the tissue CPU mean of those
# steps): a seat whose trainee's commands drag more tissue awake does more.
WORK_SED='s/^server: physics work per step with an organ awake ([0-9]* steps): \([0-9.]*\) node updates.*/\1/p'
TMEAN_SED='s/^server: physics work per step with an organ awake .* tissue CPU mean \([0-9.]*\) us$/\1/p'
if [ "$ROUNDS" -gt 1 ]; then
  rm -rf "$OUT"; mkdir -p "$OUT"
  for k in $(seq 1 "$ROUNDS"); do
    echo "load_bench: round $k of $ROUNDS" >&2
    bash "$0" "${ROUND_ARGS[@]}" --out "$OUT/round$k" > "$OUT/round$k.txt" 2>&1 ||
      { tail -5 "$OUT/round$k.txt" >&2; echo "load_bench.sh: round $k failed (its output: $OUT/round$k.txt)" >&2; exit 1; }
  done
  # label, sed expression [mode [vs]]: each round's seats against the mean
  # of that round's two runs of the seat alone, then the median over the
  # rounds against the median of the rounds' alone-to-alone spreads.
  # mode "work": the verdict speaks of work, not of time. vs (--beside):
  # "alone" (default) the one process's seats against the seat alone,
  # "beside" the seat beside the lab against the seat alone, "seats-beside"
  # the one process's seats against the seat beside (the band still the
  # seat alone's own spread: the noise of one seat's run).
  rounds_against_alone() {
    local k i d
    for k in $(seq 1 "$ROUNDS"); do
      d="$OUT/round$k"
      echo "$k a1 $(sed -n "$2" "$d/alone-server.log")"
      echo "$k a2 $(sed -n "$2" "$d/alone2-server.log")"
      for i in $LAB_SEATS; do echo "$k seat $(sed -n "$2" "$d/$(printf 'seat%02d' "$i")-server.log")"; done
      [ "$BESIDE" = 0 ] || echo "$k beside $(sed -n "$2" "$d/$BESIDE_SEAT-server.log")"
    done | awk -v what="$1" -v R="$ROUNDS" -v mode="${3:-time}" -v vs="${4:-alone}" '
      function med(a, n,   i, j, t) { # sorts a[1..n], returns its median
        for (i = 2; i <= n; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
        return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2 }
      NF == 3 && $3 > 0 {
        if ($2 == "a1") a1[$1] = $3; else if ($2 == "a2") a2[$1] = $3; else if ($2 == "beside") b[$1] = $3
        if ($2 == (vs == "beside" ? "beside" : "seat")) v[$1, ++nv[$1]] = $3 }
      END {
        who = vs == "beside" ? "the seat beside the lab" : "the seats"
        against = vs == "seats-beside" ? "the seat beside the lab" : "the seat alone"
        for (k = 1; k <= R; k++) {
          if (!(k in a1) || !(k in a2) || !nv[k] || (vs == "seats-beside" && !(k in b))) { printf "  %s, round %d: figures missing\n", what, k; continue }
          ref = (a1[k] + a2[k]) / 2; d = (a1[k] > a2[k] ? a1[k] - a2[k] : a2[k] - a1[k]) / ref
          if (vs == "seats-beside") ref = b[k]
          n = 0; for (i = 1; i <= nv[k]; i++) r[++n] = v[k, i] / ref
          m = med(r, n); L[++nr] = m; D[nr] = d
          if (vs == "alone")
            printf "  %s, round %d: alone %.1f / %.1f %s (spread %.1f %%), seats %+.0f %% to %+.0f %% of their mean (median %+.0f %%)\n",
              what, k, a1[k], a2[k], mode == "work" ? "node updates" : "us", 100 * d, 100 * (r[1] - 1), 100 * (r[n] - 1), 100 * (m - 1)
        }
        if (!nr) exit
        mL = med(L, nr); mD = med(D, nr); band = 1.5 * mD
        verdict = "unchanged within noise"
        if (mL - 1 > band) verdict = (mode == "work" ? "more than " : "slower than ") against " beyond noise"
        if (1 - mL > band) verdict = mode == "work" ? "less than " against " beyond noise" : "no slower than " against " (faster beyond noise)"
        printf "  %s over %d rounds: %s %+.1f %% against %s (rounds %+.0f %% to %+.0f %%); the seat alone'\''s own spread %.1f %% (rounds %.1f-%.1f %%), band +-%.1f %%: %s\n",
          what, nr, who, 100 * (mL - 1), against, 100 * (L[1] - 1), 100 * (L[nr] - 1), 100 * mD, 100 * D[1], 100 * D[nr], 100 * band, verdict }'
  }
  # The tissue step at equal work: each round's seats' (work, tissue CPU
  # mean) pairs on a line through their mean, with one slope for all rounds
  # (least squares over every seat of every round, each round about its own
  # mean: the CPU an extra node update costs is the machine's, and a round's
  # seats may all have done about the same work), read at the work each run
  # of the seat alone did, against that run's own tissue CPU mean; the band
  # from the two runs of the seat alone set against each other along it.
  rounds_at_equal_work() {
    local k i d
    for k in $(seq 1 "$ROUNDS"); do
      d="$OUT/round$k"
      echo "$k a1 $(sed -n "$WORK_SED" "$d/alone-server.log") $(sed -n "$TMEAN_SED" "$d/alone-server.log")"
      echo "$k a2 $(sed -n "$WORK_SED" "$d/alone2-server.log") $(sed -n "$TMEAN_SED" "$d/alone2-server.log")"
      for i in $LAB_SEATS; do
        f="$d/$(printf 'seat%02d' "$i")-server.log"
        echo "$k seat $(sed -n "$WORK_SED" "$f") $(sed -n "$TMEAN_SED" "$f")"
      done
    done | awk -v R="$ROUNDS" '
      function med(a, n,   i, j, t) {
        for (i = 2; i <= n; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
        return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2 }
      function abs(x) { return x < 0 ? -x : x }
      NF == 4 && $3 > 0 && $4 > 0 {
        if ($2 == "a1") { w1[$1] = $3; t1[$1] = $4 } else if ($2 == "a2") { w2[$1] = $3; t2[$1] = $4 }
        else { n = ++ns[$1]; sw[$1, n] = $3; st[$1, n] = $4 } }
      END {
        what = "  tissue CPU mean at the seat alone'\''s work (a line through the seats'\'' work and tissue CPU)"
        sxx = 0; sxy = 0; N = 0; W = 0
        for (k = 1; k <= R; k++) {
          n = ns[k]; if (!n) continue
          mw = 0; mt = 0; for (i = 1; i <= n; i++) { mw += sw[k, i]; mt += st[k, i] }
          MW[k] = mw / n; MT[k] = mt / n; N += n; W += mw
          for (i = 1; i <= n; i++) { sxx += (sw[k, i] - MW[k]) ^ 2; sxy += (sw[k, i] - MW[k]) * (st[k, i] - MT[k]) }
        }
        b = sxx > 0 ? sxy / sxx : 0
        # A slope needs seats whose work differs (a spread of 5 % of the
        # work at least) and must come out positive; else no reading.
        if (!N || sqrt(sxx / N) < 0.05 * W / N || b <= 0) {
          printf "%s: not read: the seats'\'' work differs too little within the rounds to fit what a node update costs (spread %.1f %% of their work, slope %.1f ns); compare the physics work line above\n",
            what, N ? 100 * sqrt(sxx / N) / (W / N) : 0, 1000 * b
          exit
        }
        for (k = 1; k <= R; k++) {
          n = ns[k]
          if (!(k in w1) || !(k in w2) || !n) { printf "%s, round %d: figures missing\n", what, k; continue }
          mw = MW[k]; mt = MT[k]; lo = sw[k, 1]; hi = lo
          for (i = 1; i <= n; i++) { if (sw[k, i] < lo) lo = sw[k, i]; if (sw[k, i] > hi) hi = sw[k, i] }
          p1 = mt + b * (w1[k] - mw); p2 = mt + b * (w2[k] - mw)
          r = (p1 / t1[k] + p2 / t2[k]) / 2
          dd = abs(t2[k] - (t1[k] + b * (w2[k] - w1[k]))) / ((t1[k] + t2[k]) / 2)
          L[++nr] = r; D[nr] = dd
          printf "%s, round %d: alone %.1f / %.1f us at %.0f / %.0f node updates (apart %.1f %% at equal work), seats %.0f-%.0f node updates, %.1f us at their mean %.0f: %+.0f %%\n",
            what, k, t1[k], t2[k], w1[k], w2[k], 100 * dd, lo, hi, mt, mw, 100 * (r - 1)
        }
        if (!nr) exit
        mL = med(L, nr); mD = med(D, nr); band = 1.5 * mD
        verdict = "unchanged within noise"
        if (mL - 1 > band) verdict = "slower than the seat alone beyond noise"
        if (1 - mL > band) verdict = "no slower than the seat alone (faster beyond noise)"
        printf "%s: %.1f ns of tissue CPU per node update (one slope, %d rounds)\n", what, 1000 * b, nr
        printf "%s over %d rounds: the seats %+.1f %% against the seat alone (rounds %+.0f %% to %+.0f %%); the seat alone'\''s own spread at equal work %.1f %% (rounds %.1f-%.1f %%), band +-%.1f %%: %s\n",
          what, nr, 100 * (mL - 1), 100 * (L[1] - 1), 100 * (L[nr] - 1), 100 * mD, 100 * D[1], 100 * D[nr], 100 * band, verdict }'
  }
  {
    echo "load_bench: $ROUNDS rounds of (the seat alone $BASELINE s, the lab $DURATION s, the seat alone again $BASELINE s); each round's summary in $OUT/roundK/summary.txt"
    sed -n '1,4p' "$OUT/round1/summary.txt"
    rounds_against_alone "step CPU median" "$STEP_SED"
    rounds_against_alone "  of it the tissue step" "$TISSUE_SED"
    rounds_against_alone "  the rest (commands, feedback, inputs, frames)" "$REST_SED"
    if [ "$BESIDE" = 1 ]; then # the same three, for the seat beside the lab and against it
      for vs in beside seats-beside; do
        rounds_against_alone "step CPU median" "$STEP_SED" time "$vs"
        rounds_against_alone "  of it the tissue step" "$TISSUE_SED" time "$vs"
        rounds_against_alone "  the rest (commands, feedback, inputs, frames)" "$REST_SED" time "$vs"
      done
    fi
    if grep -q '^server: physics work per step' "$OUT/round1/alone-server.log"; then
      rounds_against_alone "physics work (node updates per step with an organ awake)" "$WORK_SED" work
      rounds_at_equal_work
      [ "$BESIDE" = 0 ] || rounds_against_alone "physics work (node updates per step with an organ awake)" "$WORK_SED" work beside
    fi
    for k in $(seq 1 "$ROUNDS"); do
      rt=$(sed -n 's/^server: step CPU time median .*; \([0-9.]*\) simulated s per wall s.*/\1/p' "$OUT/round$k"/seat*-server.log | sort -g | head -1)
      dl=$(sed -n 's/^  delta latency: median of the subscribers. medians \([0-9.n/a]*\) us, worst p99 \([0-9.n/a]*\) us/median \1 us, worst p99 \2 us/p' "$OUT/round$k/summary.txt")
      kf=$(sed -n 's/^  time to first keyframe after joining: //p' "$OUT/round$k/summary.txt")
      late=$(sed -n 's/^SUMMARY .* late_ticks=\([0-9]*\).*/\1/p' "$OUT/round$k"/seat*-haptic.log | sort -n | tail -1)
      echo "  round $k: lowest real-time ratio ${rt:-n/a}; delta latency ${dl:-n/a}; first keyframe ${kf:-n/a}; trainees at most ${late:-n/a} ticks late"
    done
  } | tee "$OUT/summary.txt"
  exit 0
fi
rm -rf "$OUT"; mkdir -p "$OUT"
"$BUILD/server/viscera-server" --scene "$SCENE" --check > "$OUT/check.txt" ||
  { echo "load_bench.sh: the scene does not load" >&2; exit 2; }
TRAJ="$OUT/press_release.traj"
if [ "$BUSY" = 1 ]; then
  # Down 8 mm in 0.5 s, then sweep 5 mm either side in x every 2 s without
  # letting go, for the whole run: every step moves the tissue.
  { echo "0 0.012 0.004 0.07"; echo "0.5 0.012 0.004 0.027"; t=1
    while [ $t -lt $((DURATION + 4)) ]; do
      echo "$t 0.017 0.004 0.027"; echo "$((t + 1)) 0.007 0.004 0.027"; t=$((t + 2)); done; } > "$TRAJ"
else
  # Press 8 mm, hold, release, every 4 s, for the whole run.
  { t=0; echo "0 0.012 0.004 0.07"; while [ $t -lt $((DURATION + 4)) ]; do
      echo "$t.5 0.012 0.004 0.07"; echo "$((t + 1)).5 0.012 0.004 0.027"; echo "$((t + 2)).5 0.012 0.004 0.027"
      echo "$((t + 3)).9 0.012 0.004 0.07"; t=$((t + 4)); done; } > "$TRAJ"
fi
awake_line() { # server log -> "asleep in P % of steps; steps that stepped the organ: ..." (or nothing)
  sed -n 's/^server: organs slept .* every organ asleep in [0-9]* of [0-9]* steps (\([0-9.]*\) %); steps with an organ awake ([0-9]* recent): wall median \([0-9.]*\) us p99 \([0-9.]*\) us, CPU median \([0-9.]*\) us p99 \([0-9.]*\) us/asleep in \1 % of steps; steps that stepped the organ: wall median \2 us, p99 \3 us; CPU median \4 us, p99 \5 us/p' "$1"
}
step_line() { # server log -> "N steps, step wall time ...; step CPU time ...; real-time ratio R"
  local wall cpu
  wall=$(sed -n 's/^server: \([0-9]*\) steps, step time median \([0-9.]*\) us p99 \([0-9.]*\) us.*/\1 steps, step wall time median \2 us, p99 \3 us/p' "$1")
  cpu=$(sed -n 's/^server: step CPU time median \([0-9.]*\) us p99 \([0-9.]*\) us; \([0-9.]*\) simulated.*/step CPU time median \1 us, p99 \2 us; real-time ratio \3/p' "$1")
  echo "$wall; $cpu"
}
# The reference: one seat alone, scheduled as the lab's seats are; run
# before the lab (TAG alone) and again after it (alone2): the two runs'
# difference is the reference's own run-to-run spread.
run_alone() { # TAG: files OUT/TAG-*
  local tag=$1 srv p subs=()
  echo "load_bench: $([ "$tag" = alone ] && echo baseline || echo "baseline again"), one seat alone for $BASELINE s" >&2
  "${SRV_PIN[@]}" "$BUILD/server/viscera-server" --scene "$SCENE" --partition "load/$tag" --duration $((BASELINE + 2)) --quiet \
    "${SRV_RT[@]}" > "$OUT/$tag-server.out" 2> "$OUT/$tag-server.log" &
  srv=$!
  sleep 1
  # Its share of the lab's subscribers (a seat's step writes the meshes they read).
  for k in $(seq 1 $(( (SUBS + SEATS - 1) / SEATS ))); do
    "${CLI_PIN[@]}" "$BUILD/tests/bench/delta_sub" --partition "load/$tag" --duration "$BASELINE" --name "$tag-sub$k" \
      > "$OUT/$tag-sub$k.out" 2>&1 &
    subs+=($!)
  done
  "${CLI_PIN[@]}" "$BUILD/client/haptic/viscera-haptic" --partition "load/$tag" --trajectory "$TRAJ" --start-on-answer \
    --duration "$BASELINE" --quiet \
    "${HAP_RT[@]}" > "$OUT/$tag-haptic.log" 2>&1 || true
  wait "$srv" || true
  for p in "${subs[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  wait "${subs[@]}" 2>/dev/null || true
}
run_alone alone
pids=()
cleanup() { for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT
# Every process of the lab, for the CPU by kind: "pid kind name command".
: > "$OUT/procs.txt"
register() { echo "$1 $2 $3 $4" >> "$OUT/procs.txt"; }
now_us() { echo "${EPOCHREALTIME/[.,]/}"; } # bash 5; the decimal sign follows the locale
T0=$(now_us)
servers=() srvnames=()
start_seat_server() { # seatNN: a server process of its own for that seat of the lab
  "${SRV_PIN[@]}" "$BUILD/server/viscera-server" --scene "$SCENE" --partition "load/$1" --duration $((DURATION + 3)) --quiet \
    "${SRV_RT[@]}" > "$OUT/$1-server.out" 2> "$OUT/$1-server.log" &
  servers+=($!); srvnames+=("$1"); pids+=($!); register $! server "$1" viscera-server
}
if [ "$ONE" = 1 ]; then
  "${SRV_PIN[@]}" "$BUILD/server/viscera-server" --scene "$SCENE" --partition load --seats "$GROUPED" --duration $((DURATION + 3)) \
    --quiet "${SRV_RT[@]}" "${GROUPS_OPT[@]}" > "$OUT/seats-server.out" 2> "$OUT/seats-server.log" &
  servers+=($!); srvnames+=(seats); pids+=($!); register $! server seats viscera-server
  [ "$BESIDE" = 0 ] || start_seat_server "$BESIDE_SEAT"
else
  for i in $(seq 1 "$SEATS"); do start_seat_server "$(printf 'seat%02d' "$i")"; done
fi
sleep 1
for i in $(seq 1 "$SEATS"); do
  s=$(printf 'seat%02d' "$i")
  "${CLI_PIN[@]}" "$BUILD/client/haptic/viscera-haptic" --partition "load/$s" --trajectory "$TRAJ" --start-on-answer \
    --duration "$DURATION" --quiet \
    "${HAP_RT[@]}" > "$OUT/$s-haptic.log" 2>&1 &
  pids+=($!); register $! trainee "$s" viscera-haptic
done
late=$((SUBS / 3)); early=$((SUBS - late))
start_sub() { # index, duration
  local s; s=$(printf 'seat%02d' $(( ($1 % SEATS) + 1 )))
  "${CLI_PIN[@]}" "$BUILD/tests/bench/delta_sub" --partition "load/$s" --duration "$2" --name "sub$1-$s" > "$OUT/sub$1.out" 2>&1 &
  pids+=($!); register $! subscriber "sub$1-$s" delta_sub
}
for k in $(seq 1 "$early"); do start_sub "$k" "$DURATION"; done
echo "load_bench: $SEATS seats, $SUBS subscribers ($late join late), $DURATION s; samples every 10 s (CPU of every process every 1 s)" >&2
echo "t_s,seat,pid,cpu_s,rss_kb" > "$OUT/load.csv"
echo "t_s,kind,name,pid,cpu_s" > "$OUT/cpu.csv"
HZ=$(getconf CLK_TCK)
# A process may end at any moment (a server's duration, a crash): everything
# read from /proc here tolerates a missing file, so `set -e` cannot end the
# benchmark on it (it did: "awk: cannot open /proc/PID/stat").
sample() { # servers' CPU time and resident memory -> load.csv
  local t=$1 i=0 p st cpu rss
  for p in "${servers[@]}"; do
    i=$((i + 1))
    local name=${srvnames[$((i - 1))]}
    st=$(cat /proc/"$p"/stat 2>/dev/null) || continue
    # utime + stime in clock ticks (fields 14, 15; 12, 13 after the command name).
    cpu=$(echo "${st##*) }" | awk -v hz="$HZ" '{ print ($12 + $13) / hz }')
    rss=$(awk '/VmRSS/ { print $2 }' /proc/"$p"/status 2>/dev/null || true)
    [ -n "$rss" ] || continue # ended between the two reads (a zombie has no VmRSS)
    echo "$t,$name,$p,$cpu,$rss" >> "$OUT/load.csv"
  done
}
sample_cpu() { # every registered process still there (a zombie too: its times are final) -> cpu.csv
  local files=() p us
  while read -r p _; do files+=("/proc/$p/stat"); done < "$OUT/procs.txt"
  [ ${#files[@]} -gt 0 ] || return 0
  us=$(( $(now_us) - T0 ))
  { cat "${files[@]}" 2>/dev/null || true; } |
    awk -v t="$((us / 1000000)).$(printf %03d $(( (us / 1000) % 1000 )))" -v hz="$HZ" '
      NR == FNR { kind[$1] = $2; name[$1] = $3; comm[$1] = $4; next }
      { pid = $1; c = $0; sub(/\) .*$/, "", c); sub(/^[^(]*\(/, "", c); sub(/^.*\) /, "")
        # a pid the kernel gave to another program since is not ours
        if (pid in kind && c == comm[pid]) printf "%s,%s,%s,%s,%.2f\n", t, kind[pid], name[pid], pid, ($12 + $13) / hz }' \
      "$OUT/procs.txt" - >> "$OUT/cpu.csv"
}
loop0=$(now_us); t=0; late_started=0; next_mem=0
while [ $t -lt "$DURATION" ]; do
  if [ $late_started = 0 ] && [ $t -ge $((DURATION / 3)) ]; then
    for k in $(seq $((early + 1)) "$SUBS"); do start_sub "$k" $((DURATION - t)); done
    late_started=1
  fi
  if [ $t -ge $next_mem ]; then sample $t; next_mem=$((next_mem + 10)); fi
  sample_cpu
  sleep 1; t=$(( ($(now_us) - loop0) / 1000000 ))
done
sample $t
sample_cpu
wait "${servers[@]}" 2>/dev/null || true
if [ "$ONE" = 1 ]; then
  # One log per seat, as one process per seat writes (seat_logs.sh).
  split_seat_log "$OUT/seats-server.log" "$OUT" load server.log
  split_seat_log "$OUT/seats-server.out" "$OUT" load server.out
fi
# The subscribers and trainees end with the run too; wait (at most 15 s) until
# each has written its summary line, or the report would miss the last ones.
for _ in $(seq 1 15); do
  alive=0
  for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
  [ $alive = 0 ] && break
  sleep 1
done
pids=()
run_alone alone2
{
  echo "load_bench: $SEATS seats x $SCENE_NAME $([ "$ONE" = 1 ] && { [ "$NTHREADS" -lt "$GROUPED" ] && echo "in one server process ($NTHREADS physics thread$([ "$NTHREADS" = 1 ] || echo s), each stepping its seats in turn) " || echo "in one server process (a physics thread per seat) "; } || echo "in a server process each ")$([ "$BESIDE" = 1 ] && echo "but $BESIDE_SEAT, beside them in a process of its own as the seat alone runs ")($(sed -n 's/.*organ .\(.*\).: model \([a-z_]*\),.* \([0-9]*\) nodes.*/\1, \2, \3 nodes/p' "$OUT/check.txt" | head -1 | grep . || echo "see the scene"), 1 kHz physics), $([ "$BUSY" = 1 ] && echo "every seat pressed all the time" || echo "press and release every 4 s"), $SUBS subscribers ($late late), $DURATION s"
  sched() { # what PRIO LOG...: the policy asked and how many processes refused it
    local what=$1 prio=$2; shift 2
    if [ "$prio" = 0 ]; then echo "$what normal scheduling"; return; fi
    echo "$what SCHED_FIFO $prio (refused in $(grep -l 'warning: SCHED_FIFO [0-9]* refused' "$@" 2>/dev/null | wc -l) of $#)"
  }
  echo "  scheduling: $(sched "servers' physics loops" "$RTPRIO" "$OUT"/*-server.log), $(sched "trainees' loops" "$HRTPRIO" "$OUT"/*-haptic.log)"
  if [ -n "$WAKE" ]; then # the servers' and trainees' own words (refused: a warning each)
    echo "  CPU wake-up latency <= $WAKE us (PM QoS), alone and in the lab: refused by $(grep -l 'cpu-wake-latency .* refused' "$OUT"/*-server.log "$OUT"/*-haptic.log 2>/dev/null | wc -l) of $(ls "$OUT"/*-server.log "$OUT"/*-haptic.log | wc -l) processes"
  else
    echo "  CPU wake-up latency: the machine's own (no PM QoS request; --cpu-wake-latency)"
  fi
  echo "  CPUs: servers on ${SRVCPUS:-any}$([ -n "$PHYCPUS" ] && echo " (their physics loops on $PHYCPUS)"), trainees and subscribers on ${CLICPUS:-any}"
  playout_sum() { # LOG...: the servers' command playout lines summed
    sed -n 's/^server: command playout (up to \([0-9]*\) step(s)): \([0-9]*\) commands waited.* \([0-9]*\) superseded.* \([0-9]*\) dropped.*/\1 \2 \3 \4/p' "$@" 2>/dev/null |
      awk '{ d = $1; w += $2; s += $3; c += $4; n++ } END { if (n) printf "up to %d step(s): %d commands waited, %d superseded, %d dropped to catch up (%d server(s))", d, w, s, c, n; else printf "no command playout line" }'
  }
  echo "  command playout, the lab: $(playout_sum "$OUT"/seat[0-9]*-server.log); the seat alone: $(playout_sum "$OUT/alone-server.log" "$OUT/alone2-server.log")"
  echo "  alone (baseline, $BASELINE s): $(step_line "$OUT/alone-server.log")"
  echo "  alone again after the lab: $(step_line "$OUT/alone2-server.log")"
  for i in $(seq 1 "$SEATS"); do
    s=$(printf 'seat%02d' "$i")
    echo "  $s$([ "$BESIDE" = 1 ] && [ "$s" = "$BESIDE_SEAT" ] && echo " (beside the lab, its own process)"): $(step_line "$OUT/$s-server.log")"
  done
  # The lab's seats against the seat alone (issue 17 item 6: "step time
  # unchanged from one seat alone"), step CPU medians: the whole step, then
  # its two parts (the server's "step CPU split" line: the runtime's tissue
  # step, and the rest: commands, feedback, inputs, frames).
  # "Unchanged within noise": every seat's median inside the span of the two
  # runs of the seat alone, widened on each side by their difference (the
  # reference's spread as measured in this run; see the header).
  # With --beside, the same for the seat beside the lab (who "the seat
  # beside the lab", seats: the last).
  against_alone() { # label, sed expression printing one number from a server log [, who, seat numbers]
    local a1 a2
    a1=$(sed -n "$2" "$OUT/alone-server.log")
    a2=$(sed -n "$2" "$OUT/alone2-server.log")
    for i in ${4:-$LAB_SEATS}; do sed -n "$2" "$OUT/$(printf 'seat%02d' "$i")-server.log"; done | sort -g |
      awk -v a1="${a1:-0}" -v a2="${a2:-0}" -v what="$1" -v who="${3:-seats}" 'NF { v[++n] = $1 } END {
        if (!n || a1 <= 0) exit
        printf "  %s, %s against the seat alone: %+.0f %% to %+.0f %% (%.1f-%.1f us against %.1f us)", what, who,
          100 * (v[1] / a1 - 1), 100 * (v[n] / a1 - 1), v[1], v[n], a1
        if (a2 > 0) {
          lo = (a1 < a2 ? a1 : a2); hi = (a1 < a2 ? a2 : a1); d = hi - lo
          verdict = "unchanged within noise"
          if (v[1] < lo - d) verdict = "no slower than the seat alone (faster beyond noise)"
          if (v[n] > hi + d) verdict = "slower than the seat alone beyond noise"
          printf "; alone again %.1f us (%+.0f %%): %s", a2, 100 * (a2 / a1 - 1), verdict
        }
        printf "\n" }'
  }
  against_alone "step CPU median" "$STEP_SED"
  against_alone "  of it the tissue step" "$TISSUE_SED"
  against_alone "  the rest (commands, feedback, inputs, frames)" "$REST_SED"
  if [ "$BESIDE" = 1 ]; then
    against_alone "step CPU median" "$STEP_SED" "the seat beside the lab" "$SEATS"
    against_alone "  of it the tissue step" "$TISSUE_SED" "the seat beside the lab" "$SEATS"
  fi
  if grep -q '^server: physics work per step' "$OUT/alone-server.log"; then # the tissue step's work (WORK_SED)
    echo "  physics work (node updates per step with an organ awake): alone $(sed -n "$WORK_SED" "$OUT/alone-server.log"), seats $(
      for i in $LAB_SEATS; do sed -n "$WORK_SED" "$OUT/$(printf 'seat%02d' "$i")-server.log"; done | sort -g |
        awk 'NF { v[++n] = $1 } END { if (n) printf "%s-%s", v[1], v[n]; else printf "n/a" }'
    )$([ "$BESIDE" = 1 ] && echo ", the seat beside the lab $(sed -n "$WORK_SED" "$OUT/$BESIDE_SEAT-server.log")"), alone again $(sed -n "$WORK_SED" "$OUT/alone2-server.log")"
  fi
  if [ -n "$(awake_line "$OUT/alone-server.log")" ]; then
    echo "  organ sleeping: alone: $(awake_line "$OUT/alone-server.log")"
    for i in $(seq 1 "$SEATS"); do
      s=$(printf 'seat%02d' "$i"); echo "    $s: $(awake_line "$OUT/$s-server.log")"
    done
  fi
  field() { sed -n "s/^SUB.* $1=\([0-9.e+-]*\).*/\1/p" "$OUT"/sub*.out | sort -g; }
  n=$(grep -h '^SUB' "$OUT"/sub*.out | wc -l)
  got=$(grep -h '^SUB' "$OUT"/sub*.out | grep -vc ' keyframes=0 ' || true)
  deltas=$(field deltas | awk '{ s += $1 } END { print s + 0 }')
  mid() { awk '{ v[NR] = $1 } END { if (NR) print v[int((NR + 1) / 2)]; else print "n/a" }'; }
  top() { awk '{ v = $1 } END { print (NR ? v : "n/a") }'; }
  echo "  subscribers: $n of $SUBS reported, with a keyframe: $got, deltas received: $deltas"
  echo "  delta latency: median of the subscribers' medians $(field latency_us_median | mid) us, worst p99 $(field latency_us_p99 | top) us"
  echo "  time to first keyframe after joining: median $(field first_keyframe_ms | mid) ms, max $(field first_keyframe_ms | top) ms"
  awk -F, 'NR > 1 { if (!($2 in c0)) { c0[$2] = $4; r0[$2] = $5; t0[$2] = $1 } c1[$2] = $4; r1[$2] = $5; t1[$2] = $1 }
    END { for (s in c0) { dt = t1[s] - t0[s]; printf "  %s: CPU %.0f %% of a core, RSS %d kB at start, %d kB at end\n", s,
            (dt > 0 ? 100 * (c1[s] - c0[s]) / dt : 0), r0[s], r1[s] } }' "$OUT/load.csv" | sort
  # Each trainee's own figures (viscera-haptic's SUMMARY line).
  trainee() {
    sed -n 's/^SUMMARY .*rate_hz=\([0-9.]*\) .* latency_us_median=\([0-9.]*\) latency_us_p99=\([0-9.]*\) .* jitter_us_p99=\([0-9.]*\) late_ticks=\([0-9]*\).*/rate \1 Hz, \5 ticks over 1 ms late, jitter p99 \4 us, command->feedback latency median \2 us, p99 \3 us/p' "$1" | grep . ||
      echo "no SUMMARY line (see $1)"
  }
  echo "  alone trainee: $(trainee "$OUT/alone-haptic.log")"
  for i in $(seq 1 "$SEATS"); do
    s=$(printf 'seat%02d' "$i")
    echo "  $s trainee: $(trainee "$OUT/$s-haptic.log")"
  done
  # The machine's total demand: CPU time (utime + stime) each process used up
  # to its last sample, summed by kind, over the lab's wall time so far.
  awk -F, -v cores="$(nproc)" 'NR > 1 { if ($5 > m[$4]) m[$4] = $5; kind[$4] = $2; if ($1 > wall) wall = $1 }
    END { for (p in m) { c[kind[p]] += m[p]; n[kind[p]]++; all += m[p] }
          if (wall <= 0) { print "  CPU by kind: no samples"; exit }
          printf "  CPU by kind over the lab'\''s %.0f s (%% of one core; %d cores = %d %%):", wall, cores, 100 * cores
          split("server trainee subscriber", ks, " ")
          for (i = 1; i <= 3; i++) { k = ks[i]
            printf " %d %ss %.0f %% (%.1f %% each),", n[k], k, 100 * c[k] / wall, n[k] ? 100 * c[k] / wall / n[k] : 0 }
          printf " all %.0f %%\n", 100 * all / wall }' "$OUT/cpu.csv"
} | tee "$OUT/summary.txt"
