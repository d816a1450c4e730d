#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Command -> feedback latency before/after "feedback before the tissue step"
# (issue 17 item 5): RUNS short sessions per server build (the haptic
# client is NEW_BUILD's in both: only the server differs), the two builds
# interleaved (run i: old then new for odd i, new then old for even i), each
# a real server on the default scene and a scripted haptic client
# (palpate_kidney.traj, SECONDS s) over DDS on loopback, the client started
# after a random 0..999 us sleep so the phase between the client's and the
# server's 1 kHz ticks differs from run to run. Each run's figure is the
# haptic client's mean round trip (SUMMARY latency_us_mean: its command's
# send time to the arrival of the first ContactFeedback echoing it).
# Then the floor: half a 1 ms step (the mean wait of a command for the next
# step start, uniformly phased) + the DDS round trip measured by Cyclone's
# ddsperf ping/pong on the same machine (when installed; else stated).
# Prints one row per run and a table of mean of means; states the load.
# HAPTIC_RATE=HZ (environment) runs the client's loop at HZ instead of
# 1000 (e.g. 999: its phase against the server's steps then sweeps the whole
# millisecond once a second, so every run averages over all phases and the
# run-to-run spread of a fixed random phase, about 300 us, goes away).
# RT_PRIORITY=N (environment) runs both 1 kHz loops SCHED_FIFO at N (their
# --rt-priority: the loop threads only, DDS threads stay normal), as
# deploy/bench.sh does; unset, both run at normal priority.
# OLD_ARGS="..." and NEW_ARGS="..." (environment) add those options to the
# old and the new build's server (e.g. OLD_BUILD = NEW_BUILD and NEW_ARGS=
# "--command-playout 1": the same server without and with the command
# playout); the table then names the two by their options instead of by
# feedback before the step.
# usage: feedback_first_bench.sh NEW_BUILD OLD_BUILD SRC OUT [RUNS] [SECONDS]
set -euo pipefail
NEW="$1"; OLD="$2"; SRC="$3"; OUT="$4"; RUNS="${5:-10}"; SECS="${6:-3}"
D="${VISCERA_DOMAIN:-228}"
export CYCLONEDDS_URI="${CYCLONEDDS_URI:-file://$SRC/deploy/cyclonedds-loopback.xml}"
mkdir -p "$OUT"
rt=() hrate=() oldargs=() newargs=()
[ -n "${OLD_ARGS:-}" ] && read -r -a oldargs <<<"$OLD_ARGS"
[ -n "${NEW_ARGS:-}" ] && read -r -a newargs <<<"$NEW_ARGS"
[ -n "${RT_PRIORITY:-}" ] && rt=(--rt-priority "$RT_PRIORITY")
[ -n "${HAPTIC_RATE:-}" ] && hrate=(--rate "$HAPTIC_RATE")
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT

one() { # BUILD TAG RUN: prints latency_us_mean latency_us_median
  local b="$1" tag="$2" i="$3" part="fbbench/$2$3" extra=()
  if [ "$tag" = old ]; then extra=("${oldargs[@]}"); else extra=("${newargs[@]}"); fi
  "$b/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --domain "$D" --partition "$part" --quiet "${rt[@]}" \
    "${extra[@]}" \
    >"$OUT/$tag$i.server.out" 2>"$OUT/$tag$i.server.log" &
  local s=$!; pids+=("$s")
  sleep 1.2
  sleep "$(printf '0.%06d' $((RANDOM % 1000)))"
  "$NEW/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/palpate_kidney.traj" --domain "$D" \
    --partition "$part" --duration "$SECS" "${rt[@]}" "${hrate[@]}" >"$OUT/$tag$i.haptic.out" 2>"$OUT/$tag$i.haptic.log" || true
  kill -INT $s; wait $s 2>/dev/null || true
  pids=()
  local sum; sum=$(grep '^SUMMARY ' "$OUT/$tag$i.haptic.out" || true)
  local mean med
  mean=$(echo "$sum" | tr ' ' '\n' | sed -n 's/^latency_us_mean=//p')
  med=$(echo "$sum" | tr ' ' '\n' | sed -n 's/^latency_us_median=//p')
  echo "${mean:-nan} ${med:-nan}"
}

loops="normal priority"; [ -n "${RT_PRIORITY:-}" ] && loops="SCHED_FIFO $RT_PRIORITY"
echo "load before: $(uptime); loops: $loops"
: >"$OUT/runs.txt"
for i in $(seq 1 "$RUNS"); do
  if [ $((i % 2)) -eq 1 ]; then order="old new"; else order="new old"; fi
  for tag in $order; do
    b="$NEW"; [ "$tag" = old ] && b="$OLD"
    r=$(one "$b" "$tag" "$i")
    echo "run $i $tag mean_us=${r% *} median_us=${r#* }" | tee -a "$OUT/runs.txt"
  done
done
echo "load after: $(uptime)"

# DDS round trip on this machine: ddsperf ping/pong, 64-byte samples (a
# ContactFeedback is ~80 bytes), 1 kHz, same loopback configuration.
rtt="nan"
if command -v ddsperf >/dev/null; then
  ddsperf -i "$D" -D 8 pong >"$OUT/pong.log" 2>&1 & p=$!; pids+=("$p")
  sleep 0.5
  ddsperf -i "$D" -D 6 ping 1000Hz size 64 >"$OUT/ping.log" 2>&1 || true
  kill $p 2>/dev/null || true; wait $p 2>/dev/null || true
  pids=()
  # Lines like "... mean 123.456us min ..." per second: the median of the
  # per-second means (a second with a stall or a timeout does not move it).
  rtt=$(grep -o 'mean [0-9.]*us' "$OUT/ping.log" | awk '{sub("us","",$2); print $2}' | sort -g |
    awk '{v[NR] = $1} END {if (NR) printf "%.1f", NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2; else print "nan"}')
fi

# Per build: the mean of the runs' means (the issue's figure) and, as a
# check against the load's stalls, the median of the runs' means.
med() { grep " $1 " "$OUT/runs.txt" | sed -n 's/.*mean_us=\([0-9.]*\).*/\1/p' | sort -g |
  awk '{v[NR] = $1} END {if (NR) printf "%.1f", NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2; else print "nan"}'; }
old_name="old (feedback after step)" new_name="new (feedback before step)"
if [ $((${#oldargs[@]} + ${#newargs[@]})) -gt 0 ]; then
  old_name="old, ${oldargs[*]:-default options}" new_name="new, ${newargs[*]:-default options}"
fi
awk -v rtt="$rtt" -v med_old="$(med old)" -v med_new="$(med new)" -v old_name="$old_name" -v new_name="$new_name" '
  /^run / { split($4, a, "="); v = a[2]; if (v != "nan") { s[$3] += v; n[$3]++ } }
  END {
    for (t in n) m[t] = s[t] / n[t]
    printf "\n%-28s %17s %17s %5s\n", "server build", "mean of means us", "median of means", "runs"
    printf "%-28s %17.1f %17.1f %5d\n", old_name, m["old"], med_old, n["old"]
    printf "%-28s %17.1f %17.1f %5d\n", new_name, m["new"], med_new, n["new"]
    if (rtt != "nan") {
      floor = 500 + rtt
      printf "floor: half a step 500 us + DDS round trip %.1f us (ddsperf ping/pong) = %.1f us\n", rtt, floor
      printf "mean of means / floor: old %.2fx, new %.2fx; median of means / floor: old %.2fx, new %.2fx\n",
             m["old"] / floor, m["new"] / floor, med_old / floor, med_new / floor
    } else {
      print "floor: ddsperf not installed; half a step (500 us) + the DDS round trip, not measured here"
    }
  }' "$OUT/runs.txt" | tee "$OUT/summary.txt"
