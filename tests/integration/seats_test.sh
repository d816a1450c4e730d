#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Several seats in one server process (issue 17 item 6): viscera-server
# --seats 2 --partition seats runs two sessions of the classroom kidney, on
# seats/seat01 and seats/seat02, each in its own thread. Two scripted
# trainees press at the same time, one 8 mm deep in seat01, one 3 mm in
# seat02: each seat must answer its own trainee only (the deep press feels
# more than the shallow one, and each seat's summary has the peak its own

# with one summary per seat, headed by its partition. Options one process
# cannot honour for several seats are usage errors (exit 2), as are seat
# counts out of range.
set -euo pipefail
# shellcheck source=prelude.sh
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
SCENE="$SRC/assets/scenes/classroom_kidney.yaml"
SRV="$BUILD/server/viscera-server"
for bad in "--seats 0" "--seats 33" "--seats two" "--seats 2 --checkpoint $OUT/c.ckpt" "--seats 2 --final-mesh $OUT/f.obj"; do
  # shellcheck disable=SC2086 # the options are meant to split
  rc=0; "$SRV" --scene "$SCENE" $bad --duration 1 > /dev/null 2> "$OUT/bad.log" || rc=$?
  [ "$rc" = 2 ] || fail "viscera-server $bad exited $rc, not 2 (usage error): $(cat "$OUT/bad.log")"
  grep -q -- "--seats" "$OUT/bad.log" || fail "viscera-server $bad: the error does not name --seats: $(cat "$OUT/bad.log")"
done
[ -f "$OUT/c.ckpt" ] && fail "a refused --seats run wrote its checkpoint"
press() { # depth z of the probe tip (m) -> trajectory: away 0.5 s, down in 1 s, hold 1 s, up
  printf '%s\n' "0 0.012 0.004 0.07" "0.5 0.012 0.004 0.07" "1.5 0.012 0.004 $1" "2.5 0.012 0.004 $1" \
    "3.0 0.012 0.004 0.07"
}
press 0.027 > "$OUT/deep.traj"    # 8 mm into the kidney (top at z = 35 mm)
press 0.032 > "$OUT/shallow.traj" # 3 mm
"$SRV" --scene "$SCENE" --partition seats --seats 2 > "$OUT/server.out" 2> "$OUT/server.log" &
srv=$!; PIDS+=("$srv")
# Both trainees at once; each starts when its seat's scene is there (60 s at
# most, a safety stop) and exits at the end of its trajectory.
"$BUILD/client/haptic/viscera-haptic" --partition seats/seat01 --trajectory "$OUT/deep.traj" --wait-server 60 \
  --quiet > "$OUT/deep.log" 2>&1 &
h1=$!; PIDS+=("$h1")
"$BUILD/client/haptic/viscera-haptic" --partition seats/seat02 --trajectory "$OUT/shallow.traj" --wait-server 60 \
  --quiet > "$OUT/shallow.log" 2>&1 || fail "the seat02 trainee failed: $(tail -3 "$OUT/shallow.log")"
wait "$h1" || fail "the seat01 trainee failed: $(tail -3 "$OUT/deep.log")"
kill -INT "$srv"; wait "$srv" || fail "the server exited with an error: $(tail -5 "$OUT/server.log")"
# Each seat's log lines name it (one log for the process).
grep -q "^server seats/seat01: scene .* running on domain .*, partition 'seats/seat01'" "$OUT/server.log" ||
  fail "seat01 did not start (or its lines do not name it)"
grep -q "^server seats/seat02: scene .* running on domain .*, partition 'seats/seat02'" "$OUT/server.log" ||
  fail "seat02 did not start (or its lines do not name it)"
felt() { sed -n 's/^SUMMARY .*peak_force=\([0-9.]*\).*/\1/p' "$1"; }
deep=$(felt "$OUT/deep.log"); shallow=$(felt "$OUT/shallow.log")
# The seat's own summary: the lines after its SEAT line, up to the next.
seat() { # seat number, line prefix -> that line of the seat's summary
  awk -v want="partition=seats/seat0$1" -v p="^$2" '/^SEAT / { on = ($2 == want) } on && $0 ~ p' "$OUT/server.out"
}
[ "$(grep -c '^SEAT partition=seats/seat0[12] index=[12] of=2$' "$OUT/server.out")" = 2 ] ||
  fail "not one SEAT line per seat: $(grep '^SEAT' "$OUT/server.out" || echo none)"
s1=$(seat 1 SUMMARY | sed -n 's/.*peak_force=\([0-9.]*\).*/\1/p')
s2=$(seat 2 SUMMARY | sed -n 's/.*peak_force=\([0-9.]*\).*/\1/p')
c1=$(seat 1 INTAKE | sed -n 's/^INTAKE commands=\([0-9]*\) .*/\1/p')
c2=$(seat 2 INTAKE | sed -n 's/^INTAKE commands=\([0-9]*\) .*/\1/p')
echo "seat01: trainee felt ${deep:-?} N, server's peak ${s1:-?} N, ${c1:-?} commands"
echo "seat02: trainee felt ${shallow:-?} N, server's peak ${s2:-?} N, ${c2:-?} commands"
# Each press felt, the deep one clearly more (the kidney's response grows with
# depth: 8 mm gives several times the force of 3 mm), and each seat's own
# peak is its trainee's (the client renders the server's force: within 10 %).
awk -v d="${deep:-0}" -v s="${shallow:-0}" 'BEGIN { exit !(s > 0.02 && d > 1.5 * s) }' ||
  fail "the presses were not told apart: deep ${deep:-none} N, shallow ${shallow:-none} N"
awk -v a="${s1:-0}" -v b="${deep:-0}" 'BEGIN { exit !(a > 0 && a > 0.9 * b && a < 1.1 * b) }' ||
  fail "seat01's peak ${s1:-none} N is not its trainee's ${deep:-none} N"
awk -v a="${s2:-0}" -v b="${shallow:-0}" 'BEGIN { exit !(a > 0 && a > 0.9 * b && a < 1.1 * b) }' ||
  fail "seat02's peak ${s2:-none} N is not its trainee's ${shallow:-none} N"
# One trainee per seat: a seat applies at most what its own trainee sent
# (one command per tick, its own count; a few more for the release), none
# from the other seat's trainee, which would add its thousands.
ticks() { sed -n 's/^SUMMARY ticks=\([0-9]*\) .*/\1/p' "$1"; }
t1=$(ticks "$OUT/deep.log"); t2=$(ticks "$OUT/shallow.log")
for pair in "${c1:-0} ${t1:-0} seat01" "${c2:-0} ${t2:-0} seat02"; do
  read -r c t name <<< "$pair"
  [ "$c" -gt 0 ] && [ "$t" -gt 0 ] && [ "$c" -le $((t + 5)) ] ||
    fail "$name applied $c commands; its trainee sent ${t} (commands from another seat's trainee?)"
done
[ "$(grep -c '^server: seat .seats/seat0[12]. ([12] of 2):$' "$OUT/server.log")" = 2 ] ||
  fail "the server log has not one figures block per seat"
echo "PASS: two seats in one process, each answering its own trainee (${deep} N and ${shallow} N)"
