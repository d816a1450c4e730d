#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Benchmarks (figures, not pass/fail): server step time per generated organ
# and MeshDelta size (bench_server), then the haptic tick and command->feedback
# latency on loopback over 60 s of palpation, then the recorder's throughput
# under two 1 kHz haptic clients and a 60 Hz gallbladder (45 s).
# Output: out/bench/server_steps.csv, out/bench/latency/*, out/bench/recorder_load/*.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$ROOT/deploy/install_deps.sh"
bash "$ROOT/deploy/build.sh" "$ROOT/build-bench" -DCMAKE_BUILD_TYPE=Release
OUT="$ROOT/out/bench"; mkdir -p "$OUT/latency"
echo "== server step time and MeshDelta size (one core, Release build)"
"$ROOT/build-bench/tests/bench/bench_server" "$ROOT/assets" "$OUT/server_steps.csv"
echo
echo "== haptic tick and command->feedback latency on loopback (server + scripted haptic client, 60 s, SCHED_FIFO when allowed)"
export CYCLONEDDS_URI="${CYCLONEDDS_URI:-file://$ROOT/deploy/cyclonedds-loopback.xml}"
D="${VISCERA_DOMAIN:-0}"
"$ROOT/build-bench/server/viscera-server" --scene "$ROOT/assets/scenes/default.yaml" --domain "$D" \
  --partition bench/latency >"$OUT/latency/server.out" 2>"$OUT/latency/server.log" & S=$!
"$ROOT/build-bench/client/haptic/viscera-haptic" --trajectory "$ROOT/assets/trajectories/palpate_kidney.traj" \
  --domain "$D" --partition bench/latency --duration 60 --rt-priority 80 >"$OUT/latency/haptic.out" 2>"$OUT/latency/haptic.log"
kill -INT $S; wait $S || true
cat "$OUT/latency/haptic.log" "$OUT/latency/server.log" | grep -E "haptic:|step time"
echo
echo "== recorder throughput and drops: gallbladder at 60 Hz, two haptic clients at 1 kHz, 45 s"
VISCERA_DOMAIN="$D" bash "$ROOT/tests/bench/recorder_load.sh" "$ROOT/build-bench" "$ROOT" "$OUT/recorder_load" 45
echo
echo "== cutting: progressive tetrahedral cutting on the spleen (docs/methods.md C Table 1 style), 100 random cuts"
"$ROOT/build-bench/tests/bench/bench_tet_cut" "$ROOT" --csv "$OUT/tet_cut.csv" --png "$OUT/tet_cut.png"
echo
echo "== cutting: three-stage mass-spring cutting, incision width over time (docs/methods.md D Fig. 6)"
"$ROOT/build-bench/tests/bench/bench_ms_cut" --out "$OUT/ms_cut"
echo
echo "== classroom load: 5 seats, 30 subscribers at 60 Hz (a third joining late), 600 s"
VISCERA_DOMAIN="$D" bash "$ROOT/deploy/load_bench.sh" --build "$ROOT/build-bench" --out "$OUT/load"
