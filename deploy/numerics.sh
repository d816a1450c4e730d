#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Numerics benchmark (docs/numerics.md): error against run time and stability for
# every deformation model and integrator. Builds a Release tree and runs
# bench_numerics on one core; writes CSV files and PNG charts into
# out/numerics/ and prints the summary table.
# Usage: deploy/numerics.sh [--quick] [more bench_numerics options]
#   --quick   the one-minute version (coarser sweeps), as the ctest smoke test runs it
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build-numerics"
OUT="$ROOT/out/numerics"
bash "$ROOT/deploy/install_deps.sh"
# Only the benchmark and what it links: a full build is not needed for it.
cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD" -j"$(nproc)" --target bench_numerics
mkdir -p "$OUT"
# One core: timings are single-threaded figures; pinning keeps the scheduler
# from moving the run between cores mid-measurement (taskset when present).
RUN=()
if command -v taskset >/dev/null 2>&1; then RUN=(taskset -c 0); fi
"${RUN[@]}" "$BUILD/tests/bench/numerics/bench_numerics" --out "$OUT" --assets "$ROOT/assets" "$@" | tee "$OUT/summary.txt"
echo "charts and CSV files: $OUT"
