#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# load_bench.sh --beside: the lab's last seat runs in a server process of its
# own (as the seat alone runs) while the other seats run in the one process.
# Asserts: --beside without --one-server, or with one seat, exits 2 and says
# why; in each of two rounds the one process stepped seats 1-2 only and
# seat 3 had its own server process (procs.txt, the split logs); the round's
# summary names the seat beside; the summary over the rounds sets the seat
# beside against the seat alone and the one process's seats against the seat
# beside, with the figures its own logs give (recomputed here) and a verdict.
# Figures are not judged (a benchmark, not a timing test).
# usage: load_beside_smoke.sh SRC BUILD OUT
set -euo pipefail
SRC="$1" BUILD="$2" OUT="$3"
rm -rf "$OUT"; mkdir -p "$(dirname "$OUT")"
fail() { echo "FAIL: $*" >&2; [ -f "$OUT/summary.txt" ] && cat "$OUT/summary.txt" >&2; exit 1; }
for bad in "--seats 3" "--one-server --seats 1"; do
  rc=0
  # shellcheck disable=SC2086 # the options are words
  bash "$SRC/deploy/load_bench.sh" --build "$BUILD" --out "$OUT" --beside $bad > /dev/null 2> "$OUT.err" || rc=$?
  [ "$rc" = 2 ] && grep -q "beside needs --one-server and 2 seats or more" "$OUT.err" ||
    fail "--beside $bad: exit $rc, expected 2: $(cat "$OUT.err")"
done
bash "$SRC/deploy/load_bench.sh" --build "$BUILD" --out "$OUT" --rounds 2 --seats 3 --subscribers 3 --duration 6 \
  --baseline 2 --one-server --seat-threads 1 --beside --rt-priority 0 --haptic-rt-priority 0 > "$OUT.log" 2>&1 ||
  { tail -20 "$OUT.log" >&2; fail "load_bench.sh --beside --rounds 2 failed"; }
S="$OUT/summary.txt"
med() { sed -n "$1" "$2"; }
STEP='s/^server: step CPU time median \([0-9.]*\) us.*/\1/p'
TISSUE='s/^server: step CPU split: tissue (contact and organs) median \([0-9.]*\) us.*/\1/p'
for k in 1 2; do
  d="$OUT/round$k"
  [ "$(awk '$2 == "server"' "$d/procs.txt" | wc -l)" = 2 ] || fail "round $k: not two server processes: $(cat "$d/procs.txt")"
  grep -q "^[0-9]* server seat03 viscera-server$" "$d/procs.txt" || fail "round $k: seat03 had no server process of its own"
  grep -q "seat 'load/seat02'" "$d/seats-server.log" || fail "round $k: the one process did not step seat02"
  ! grep -q "seat 'load/seat03'" "$d/seats-server.log" || fail "round $k: the one process stepped seat03 too"
  grep -Eq '^server: [0-9]{4,} steps' "$d/seat03-server.log" || fail "round $k: the seat beside did not step"
  grep -Eq '^  seat03 [(]beside the lab, its own process[)]: [0-9]{4,} steps' "$d/summary.txt" ||
    fail "round $k: the summary does not name the seat beside"
  grep -Eq '^  step CPU median, the seat beside the lab against the seat alone: ' "$d/summary.txt" ||
    fail "round $k: no line for the seat beside against the seat alone"
done
# The figures over the rounds, as the logs give them: the median over the
# two rounds (their mean) of the seat beside against the seat alone's two
# runs, and of the one process's seats (their median) against the seat beside.
want() { # sed, beside|seats-beside
  for k in 1 2; do
    d="$OUT/round$k"
    echo "$k $(med "$1" "$d/alone-server.log") $(med "$1" "$d/alone2-server.log") $(med "$1" "$d/seat03-server.log") $(med "$1" "$d/seat01-server.log") $(med "$1" "$d/seat02-server.log")"
  done | awk -v vs="$2" '{ r[NR] = vs == "beside" ? $4 / (($2 + $3) / 2) : (($5 + $6) / 2) / $4 }
    END { printf "%+.1f %%", 100 * ((r[1] + r[2]) / 2 - 1) }'
}
V='(unchanged within noise|slower than (the seat alone|the seat beside the lab) beyond noise|no slower than (the seat alone|the seat beside the lab) [(]faster beyond noise[)])$'
for q in "step CPU median:$STEP" "of it the tissue step:$TISSUE"; do
  what=${q%%:*} sed=${q#*:}
  line=$(grep -E "^ +$what over 2 rounds: the seat beside the lab " "$S") || fail "no '$what' line for the seat beside"
  case "$line" in *"the seat beside the lab $(want "$sed" beside) against the seat alone "*) ;;
    *) fail "'$line' is not the seat beside against the seat alone ($(want "$sed" beside))" ;; esac
  echo "$line" | grep -Eq "$V" || fail "'$line' has no verdict"
  line=$(grep -E "^ +$what over 2 rounds: the seats .* against the seat beside the lab " "$S") ||
    fail "no '$what' line for the seats against the seat beside"
  case "$line" in *"the seats $(want "$sed" seats-beside) against the seat beside the lab "*) ;;
    *) fail "'$line' is not the seats against the seat beside ($(want "$sed" seats-beside))" ;; esac
  echo "$line" | grep -Eq "$V" || fail "'$line' has no verdict"
done
grep -Eq "^  physics work [(]node updates per step with an organ awake[)] over 2 rounds: the seat beside the lab .*: (unchanged within noise|more than the seat alone beyond noise|less than the seat alone beyond noise)$" "$S" ||
  fail "no physics work line for the seat beside"
echo "the seat beside the lab: $(grep -E '^  step CPU median over 2 rounds: the seat beside' "$S")"
