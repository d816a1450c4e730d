#!/usr/bin/env bash
# Classroom load benchmark (issue 7): SEATS servers (assets/scenes/
# classroom_kidney.yaml, meshes at 60 Hz) with a scripted trainee each
# pressing and releasing for the whole run, SUBSCRIBERS light viewers
# (tests/bench/delta_sub: keyframe + every MeshDelta, latency measured) spread
# over the seats, a third of them joining late (at a third of the run).
# Samples every server's CPU time and resident memory every 10 s; at the end
# prints per-seat step time (median, p99; wall time and the server thread's
# CPU time, which tells the step's own cost from time spent preempted by the
# other processes) and real-time ratio, delta latency (median, p99 over all
# subscribers), the time late joiners waited for their keyframe, and CPU /
# memory at the start and the end of the run. Writes OUT/load.csv (samples)
# and OUT/summary.txt.
#
# Before the lab starts, one seat runs alone (same scene, same trainee, no
# subscribers) for BASELINE s: its step times are the reference that "step
# time unchanged" is judged against.
#
# Servers run their physics loop at SCHED_FIFO RT (--rt-priority), trainees
# their 1 kHz tick at HRT (higher: the haptic tick is short and the most
# latency-critical), as a lab would deploy them; 0 = normal scheduling.
# Without the privilege both warn and run at normal priority (the summary
# says which). The scene's organ sleeps while the trainee is away
# (physics.sleep_speed); the summary gives the step times of the steps that
# stepped the organ next to those of all steps. Also prints every trainee's
# tick rate and late ticks, and the CPU used by each kind of process
# (servers, trainees, subscribers) over the run, as % of one core.
#
# usage: deploy/load_bench.sh [--build DIR] [--out DIR] [--seats N] [--subscribers M] [--duration S]
#                             [--baseline S] [--rt-priority RT] [--haptic-rt-priority HRT] [--scene FILE]
# defaults: build/, out/load, 5 seats, 30 subscribers, 600 s (the issue's setting), baseline 30 s,
# RT 70, HRT 80, assets/scenes/classroom_kidney.yaml
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build" OUT="$ROOT/out/load" SEATS=5 SUBS=30 DURATION=600 BASELINE=30 RT=70 HRT=80
SCENE="$ROOT/assets/scenes/classroom_kidney.yaml"
while [ $# -gt 0 ]; do
  case "$1" in
    --build) BUILD="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --seats) SEATS="$2"; shift 2 ;;
    --subscribers) SUBS="$2"; shift 2 ;;
    --duration) DURATION="$2"; shift 2 ;;
    --baseline) BASELINE="$2"; shift 2 ;;
    --rt-priority) RT="$2"; shift 2 ;;
    --haptic-rt-priority) HRT="$2"; shift 2 ;;
    --scene) SCENE="$2"; shift 2 ;;
    -h|--help) sed -n 2,35p "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "load_bench.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
for v in SEATS SUBS DURATION BASELINE; do [[ "${!v}" =~ ^[0-9]+$ ]] && [ "${!v}" -ge 1 ] || { echo "load_bench.sh: bad ${v,,}" >&2; exit 2; }; done
for v in RT HRT; do [[ "${!v}" =~ ^[0-9]+$ ]] && [ "${!v}" -le 99 ] || { echo "load_bench.sh: bad ${v,,} (0..99)" >&2; exit 2; }; done
[ -f "$SCENE" ] || { echo "load_bench.sh: scene file not found: $SCENE" >&2; exit 2; }
SRV_RT=(); HAP_RT=()
[ "$RT" -gt 0 ] && SRV_RT=(--rt-priority "$RT")
[ "$HRT" -gt 0 ] && HAP_RT=(--rt-priority "$HRT")
[ -x "$BUILD/tests/bench/delta_sub" ] || { echo "load_bench.sh: $BUILD/tests/bench/delta_sub missing (build with -DVISCERA_BUILD_BENCH=ON)" >&2; exit 1; }
export CYCLONEDDS_URI="${CYCLONEDDS_URI:-file://$ROOT/deploy/cyclonedds-loopback.xml}"
export VISCERA_DOMAIN="${VISCERA_DOMAIN:-8}"
rm -rf "$OUT"; mkdir -p "$OUT"
# Press 8 mm, hold, release, every 4 s, for the whole run.
TRAJ="$OUT/press_release.traj"
{ t=0; echo "0 0.012 0.004 0.07"; while [ $t -lt $((DURATION + 4)) ]; do
    echo "$t.5 0.012 0.004 0.07"; echo "$((t + 1)).5 0.012 0.004 0.027"; echo "$((t + 2)).5 0.012 0.004 0.027"
    echo "$((t + 3)).9 0.012 0.004 0.07"; t=$((t + 4)); done; } > "$TRAJ"
step_line() { # server log -> "N steps, step wall time ...; step CPU time ...; real-time ratio R"
  local wall cpu
  wall=$(sed -n 's/^server: \([0-9]*\) steps, step time median \([0-9.]*\) us p99 \([0-9.]*\) us.*/\1 steps, step wall time median \2 us, p99 \3 us/p' "$1")
  cpu=$(sed -n 's/^server: step CPU time median \([0-9.]*\) us p99 \([0-9.]*\) us; \([0-9.]*\) simulated.*/step CPU time median \1 us, p99 \2 us; real-time ratio \3/p' "$1")
  echo "$wall; $cpu"
}
awake_line() { # server log -> "organ asleep in P % of steps; awake steps: wall ..., CPU ..." (or nothing)
  sed -n 's/^server: organs slept .* every organ asleep in [0-9]* of [0-9]* steps (\([0-9.]*\) %); steps with an organ awake ([0-9]* recent): wall median \([0-9.]*\) us p99 \([0-9.]*\) us, CPU median \([0-9.]*\) us p99 \([0-9.]*\) us/asleep in \1 % of steps; steps that stepped the organ: wall median \2 us, p99 \3 us; CPU median \4 us, p99 \5 us/p' "$1"
}
sched_line() { # log, requested priority -> how its loop was scheduled (--quiet hides the success line)
  if grep -q "SCHED_FIFO.*refused" "$1"; then echo "normal priority (SCHED_FIFO $2 refused)"
  elif [ "$2" -gt 0 ]; then echo "SCHED_FIFO priority $2"
  else echo "normal priority"; fi
}
cpu_of() { # pid -> utime+stime in s, or nothing when gone
  awk -v hz="$(getconf CLK_TCK)" '{ sub(/^.*\) /, ""); print ($12 + $13) / hz }' "/proc/$1/stat" 2>/dev/null || true
}
declare -A KIND LASTCPU
track() { KIND[$1]=$2; }
# The reference: one seat alone.
echo "load_bench: baseline, one seat alone for $BASELINE s" >&2
"$BUILD/server/viscera-server" --scene "$SCENE" --partition "load/alone" --duration $((BASELINE + 2)) --quiet "${SRV_RT[@]}" \
  > "$OUT/alone-server.out" 2> "$OUT/alone-server.log" &
alone=$!
sleep 1
"$BUILD/client/haptic/viscera-haptic" --partition "load/alone" --trajectory "$TRAJ" --duration "$BASELINE" --quiet "${HAP_RT[@]}" \
  > "$OUT/alone-haptic.log" 2>&1 || true
wait "$alone" || true
pids=()
cleanup() { for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT
servers=()
for i in $(seq 1 "$SEATS"); do
  s=$(printf 'seat%02d' "$i")
  "$BUILD/server/viscera-server" --scene "$SCENE" --partition "load/$s" --duration $((DURATION + 3)) --quiet "${SRV_RT[@]}" \
    > "$OUT/$s-server.out" 2> "$OUT/$s-server.log" &
  servers+=($!); pids+=($!); track $! server
done
sleep 1
for i in $(seq 1 "$SEATS"); do
  s=$(printf 'seat%02d' "$i")
  "$BUILD/client/haptic/viscera-haptic" --partition "load/$s" --trajectory "$TRAJ" --duration "$DURATION" --quiet \
    "${HAP_RT[@]}" > "$OUT/$s-haptic.log" 2>&1 & pids+=($!); track $! trainee
done
late=$((SUBS / 3)); early=$((SUBS - late))
start_sub() { # index, duration
  local s; s=$(printf 'seat%02d' $(( ($1 % SEATS) + 1 )))
  "$BUILD/tests/bench/delta_sub" --partition "load/$s" --duration "$2" --name "sub$1-$s" > "$OUT/sub$1.out" 2>&1 &
  pids+=($!); track $! subscriber
}
for k in $(seq 1 "$early"); do start_sub "$k" "$DURATION"; done
echo "load_bench: $SEATS seats, $SUBS subscribers ($late join late), $DURATION s; samples every 10 s" >&2
echo "t_s,seat,pid,cpu_s,rss_kb" > "$OUT/load.csv"
sample() {
  local t=$1 i=0 p cpu rss
  for p in "${servers[@]}"; do
    i=$((i + 1))
    # utime + stime in clock ticks (fields 14, 15 after the command name);
    # a server that has already exited is skipped.
    cpu=$(cpu_of "$p"); rss=$(awk '/VmRSS/ { print $2 }' "/proc/$p/status" 2>/dev/null || true)
    [ -n "$cpu" ] && [ -n "$rss" ] || continue
    echo "$t,seat$(printf %02d $i),$p,$cpu,$rss" >> "$OUT/load.csv"
  done
  # Every process's CPU so far (the last sample before it exits counts).
  for p in "${!KIND[@]}"; do cpu=$(cpu_of "$p"); [ -n "$cpu" ] && LASTCPU[$p]=$cpu; done
  return 0
}
t=0; late_started=0
while [ $t -lt "$DURATION" ]; do
  if [ $late_started = 0 ] && [ $t -ge $((DURATION / 3)) ]; then
    for k in $(seq $((early + 1)) "$SUBS"); do start_sub "$k" $((DURATION - t)); done
    late_started=1
  fi
  sample $t
  step=$(( DURATION - t < 10 ? DURATION - t : 10 ))
  sleep "$step"; t=$((t + step))
done
sample $t
wait "${servers[@]}" 2>/dev/null || true
sleep 1
pids=()
{
  echo "load_bench: $SEATS seats x classroom_kidney (2,000 vertices, 1 kHz physics, meshes at 60 Hz), $SUBS subscribers ($late late), $DURATION s"
  echo "  alone (baseline, $BASELINE s): $(step_line "$OUT/alone-server.log")"
  for i in $(seq 1 "$SEATS"); do
    s=$(printf 'seat%02d' "$i")
    echo "  $s: $(step_line "$OUT/$s-server.log")"
  done
  if [ -n "$(awake_line "$OUT/alone-server.log")" ]; then
    echo "  organ sleeping (the scene's physics.sleep_speed): alone: $(awake_line "$OUT/alone-server.log")"
    for i in $(seq 1 "$SEATS"); do
      s=$(printf 'seat%02d' "$i"); echo "    $s: $(awake_line "$OUT/$s-server.log")"
    done
  fi
  echo "  scheduling: servers' physics loop $(sched_line "$OUT/seat01-server.log" "$RT"), trainees' tick $(sched_line "$OUT/seat01-haptic.log" "$HRT")"
  for i in $(seq 1 "$SEATS"); do
    s=$(printf 'seat%02d' "$i")
    sed -n "s/^SUMMARY ticks=\([0-9]*\) rate_hz=\([0-9.]*\) .*latency_us_median=\([0-9.]*\) latency_us_p99=\([0-9.]*\) .*late_ticks=\([0-9]*\).*/  $s trainee: \1 ticks at \2 Hz, \5 later than 1 ms; command->feedback latency median \3 us, p99 \4 us/p" "$OUT/$s-haptic.log"
  done
  for k in server trainee subscriber; do
    tot=0; n=0
    for p in "${!KIND[@]}"; do
      [ "${KIND[$p]}" = "$k" ] && [ -n "${LASTCPU[$p]:-}" ] || continue
      tot=$(awk -v a="$tot" -v b="${LASTCPU[$p]}" 'BEGIN { print a + b }'); n=$((n + 1))
    done
    awk -v k="$k" -v t="$tot" -v n="$n" -v d="$DURATION" 'BEGIN { if (n) printf "  CPU of the %ss: %d processes, %.1f %% of one core in all over the run (%.2f %% each)\n", k, n, 100 * t / d, 100 * t / d / n }'
  done
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
} | tee "$OUT/summary.txt"
