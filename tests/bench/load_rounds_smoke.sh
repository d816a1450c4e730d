#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# load_bench.sh --rounds: the whole (seat alone, lab, seat alone again) run
# twice, each round in OUT/roundK/, and a summary over the rounds. Asserts:
# --rounds 0 / x exit 2; both rounds ran (their own summaries, their seats
# stepped); the summary's per-round figures are those rounds' own (the seat
# alone's two medians as its two server logs give them) and their seats'
# figures against the two; the verdict over the rounds for the whole step
# and its two parts; the physics work behind the tissue step (each server's
# own figure, a verdict in words of work) and the tissue step at equal work.
# Figures are not judged (a benchmark, not a timing test).
# usage: load_rounds_smoke.sh SRC BUILD OUT
set -euo pipefail
SRC="$1" BUILD="$2" OUT="$3"
rm -rf "$OUT"; mkdir -p "$(dirname "$OUT")"
fail() { echo "FAIL: $*" >&2; [ -f "$OUT/summary.txt" ] && cat "$OUT/summary.txt" >&2; exit 1; }
for bad in 0 x; do
  rc=0
  bash "$SRC/deploy/load_bench.sh" --build "$BUILD" --out "$OUT" --rounds "$bad" > /dev/null 2> "$OUT.err" || rc=$?
  [ "$rc" = 2 ] && grep -q "bad rounds" "$OUT.err" || fail "--rounds $bad: exit $rc, expected 2: $(cat "$OUT.err")"
done
bash "$SRC/deploy/load_bench.sh" --build "$BUILD" --out "$OUT" --rounds 2 --seats 2 --subscribers 2 --duration 6 \
  --baseline 2 --one-server --seat-threads 1 --rt-priority 0 --haptic-rt-priority 0 --command-playout 1 > "$OUT.log" 2>&1 ||
  { tail -20 "$OUT.log" >&2; fail "load_bench.sh --rounds 2 failed"; }
S="$OUT/summary.txt"
med() { sed -n 's/^server: step CPU time median \([0-9.]*\) us.*/\1/p' "$1"; }
for k in 1 2; do
  grep -Eq '^  seat02: [0-9]{4,} steps' "$OUT/round$k/summary.txt" || fail "round $k: the lab's seats did not step"
  a1=$(med "$OUT/round$k/alone-server.log") a2=$(med "$OUT/round$k/alone2-server.log")
  line=$(grep "^  step CPU median, round $k: " "$S") || fail "no step CPU line for round $k"
  want=$(printf 'alone %.1f / %.1f us' "$a1" "$a2")
  case "$line" in *": $want "*) ;; *) fail "round $k: '$line' does not carry the seat alone's own medians ($want)" ;; esac
  # The seats' range against the two runs' mean, as the round's seat logs give it.
  lo=$(for s in seat01 seat02; do med "$OUT/round$k/$s-server.log"; done | sort -g | head -1)
  want=$(awk -v lo="$lo" -v a1="$a1" -v a2="$a2" 'BEGIN { printf "seats %+.0f %% to", 100 * (lo / ((a1 + a2) / 2) - 1) }')
  case "$line" in *"$want"*) ;; *) fail "round $k: '$line' does not set the seats against the mean ($want)" ;; esac
  # --command-playout reached every server, and every trainee played its path from its server's answer.
  grep -Eq "^  command playout, the lab: up to 1 step\(s\): [0-9]+ commands waited, .*\(2 server\(s\)\); the seat alone: up to 1 step\(s\): .*\(2 server\(s\)\)$" \
    "$OUT/round$k/summary.txt" || fail "round $k: no command playout line of 1 step for the lab's and the seat alone's servers"
  for h in "$OUT/round$k"/*-haptic.log; do
    grep -q "^haptic: path started at [0-9.]* s of the loop (--start-on-answer)" "$h" || fail "$h: the path did not start on the answer"
  done
  grep -Eq "^  round $k: lowest real-time ratio [0-9.]+; delta latency median [0-9.]+ us" "$S" || fail "no lab figures for round $k"
done
V='(unchanged within noise|slower than the seat alone beyond noise|no slower than the seat alone [(]faster beyond noise[)])$'
for what in "step CPU median" "  of it the tissue step" "  the rest [(]commands, feedback, inputs, frames[)]"; do
  grep -Eq "^  $what over 2 rounds: the seats [-+][0-9.]+ % against the seat alone .*band [+]-[0-9.]+ %: $V" "$S" ||
    fail "no verdict over the rounds for '$what'"
done
# The physics work behind the tissue step: each server's own line, the
# round's figures taken from it, a verdict in words of work, and the tissue
# step at equal work either read or said why not.
work() { sed -n 's/^server: physics work per step with an organ awake ([0-9]* steps): \([0-9.]*\) node updates, [0-9.]* spring blocks .*; tissue CPU mean [0-9.]* us$/\1/p' "$1"; }
for k in 1 2; do
  w1=$(work "$OUT/round$k/alone-server.log") w2=$(work "$OUT/round$k/alone2-server.log")
  [ -n "$w1" ] && [ -n "$w2" ] || fail "round $k: a run of the seat alone has no physics work line"
  for s in seat01 seat02; do [ -n "$(work "$OUT/round$k/$s-server.log")" ] || fail "round $k: $s has no physics work line"; done
  want=$(printf 'alone %.1f / %.1f node updates' "$w1" "$w2")
  grep -q "^  physics work (node updates per step with an organ awake), round $k: $want " "$S" ||
    fail "round $k: the work line does not carry the seat alone's own work ($want)"
done
grep -Eq "^  physics work [(]node updates per step with an organ awake[)] over 2 rounds: .*: (unchanged within noise|more than the seat alone beyond noise|less than the seat alone beyond noise)$" "$S" ||
  fail "no verdict over the rounds for the physics work"
grep -Eq "^  tissue CPU mean at the seat alone's work .*(over 2 rounds: the seats [-+][0-9.]+ % against the seat alone .*: $V|: not read: the seats' work differs too little)" "$S" ||
  fail "no reading (nor its reason) of the tissue step at equal work"
echo "two rounds, their figures and the verdict over them: $(grep -E '^  step CPU median over' "$S")"
