#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# feedback_first_bench.sh with OLD_ARGS / NEW_ARGS: one build, two option
# sets for its server, two short runs per side. Asserts: every run of each
# side gave a mean; the table names each side by its options and counts its
# runs; each side's options reached that side's servers only (the command
# playout line with the depth that side asked for). Figures are not judged
# (a benchmark, not a timing test).
# usage: feedback_first_smoke.sh SRC BUILD OUT
set -euo pipefail
SRC="$1" BUILD="$2" OUT="$3"
rm -rf "$OUT"; mkdir -p "$OUT"
fail() { echo "FAIL: $*" >&2; [ -f "$OUT/summary.txt" ] && cat "$OUT/summary.txt" >&2; exit 1; }
OLD_ARGS="--command-playout 2" NEW_ARGS="--command-playout 1" \
  bash "$SRC/tests/bench/feedback_first_bench.sh" "$BUILD" "$BUILD" "$SRC" "$OUT" 2 1 > "$OUT.log" 2>&1 ||
  { tail -20 "$OUT.log" >&2; fail "feedback_first_bench.sh failed"; }
for side in old new; do
  for i in 1 2; do
    grep -Eq "^run $i $side mean_us=[0-9.]+ median_us=[0-9.]+$" "$OUT/runs.txt" || fail "run $i of the $side side has no mean"
  done
done
grep -Eq "^old, --command-playout 2 +[0-9.]+ +[0-9.]+ +2$" "$OUT/summary.txt" || fail "the table does not name the old side by its options"
grep -Eq "^new, --command-playout 1 +[0-9.]+ +[0-9.]+ +2$" "$OUT/summary.txt" || fail "the table does not name the new side by its options"
for i in 1 2; do
  grep -q "^server: command playout (up to 2 step(s))" "$OUT/old$i.server.log" || fail "OLD_ARGS did not reach old run $i's server"
  grep -q "^server: command playout (up to 1 step(s))" "$OUT/new$i.server.log" || fail "NEW_ARGS did not reach new run $i's server"
done
echo "two sides by their options: $(grep -E '^(old|new), ' "$OUT/summary.txt" | tr -s ' ' | paste -sd ';')"
