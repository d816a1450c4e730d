#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The command playout across a jittery link (issue 17 item 6;
# server/session/command_playout.h): the server in site a, the scripted
# trainee at 1 kHz in site b, each frame delayed 1.4-2.6 ms one way (2 ms
# +- 0.6 ms, in order), so the trainee's commands reach the server bunched:
# two in one step, none in the next. The same palpation twice:
#   - the default (--command-playout 0: the newest command at once): a
#     large share of the commands is never put into effect nor answered
#     (the test's own check that the link bunches them);
#   - --command-playout 1 (up to one step's wait): one command into effect
#     per step, so the commands never answered are at most a third of the
#     default's, so are those superseded, and the server says commands
#     waited. (Relative: on a busy machine the trainee's own late ticks
#     send bunches of three that one step's wait cannot hold; quiet, 20 of
#     5,002 unanswered against 1,150.)
# Judged from the trainee's SUMMARY (ticks, latency_samples: the commands
# answered) and the server's "command playout" line. No wall-clock check.
# usage: command_playout_test.sh BUILD SRC OUT
set -euo pipefail
source "$2/tests/network/prelude.sh"
net_sites cp1
export CYCLONEDDS_URI="file://$SRC/deploy/cyclonedds-site.xml"
# The site file without DDS Security: every program refuses it unless told (issue 14 item 5).
export VISCERA_INSECURE=1
SEAT=cp/palp
TRAJ="$SRC/assets/trajectories/palpate_kidney.traj"
LINK=(--delay 2 --jitter 0.6 --no-reorder)

net_press p0 8 3 "$TRAJ" "${LINK[@]}"
NET_SERVER_ARGS=(--command-playout 1)
net_press p1 8 3 "$TRAJ" "${LINK[@]}"

# playout NAME: "ticks answered commands delayed superseded caught_up"
playout() {
  local t a c pl
  t=$(field "$OUT/$1-haptic.out" ticks) a=$(field "$OUT/$1-haptic.out" latency_samples)
  c=$(sed -n 's/^server: \([0-9]*\) tool commands applied.*/\1/p' "$OUT/$1-server.log")
  pl=$(sed -n 's/^server: command playout (up to [0-9]* step(s)): \([0-9]*\) commands waited.* \([0-9]*\) superseded.* \([0-9]*\) dropped to catch up$/\1 \2 \3/p' \
    "$OUT/$1-server.log")
  [ -n "$t" ] && [ -n "$a" ] && [ -n "$c" ] && [ -n "$pl" ] || fail "$1: no SUMMARY or no command playout line"
  echo "$t $a $c $pl"
}
read -r t0 a0 c0 d0 s0 u0 <<<"$(playout p0)"
read -r t1 a1 c1 d1 s1 u1 <<<"$(playout p1)"
printf "%-22s %6s %9s %9s %7s %11s %9s\n" server ticks answered commands waited superseded caught_up
printf "%-22s %6s %9s %9s %7s %11s %9s\n" "default (0 steps)" "$t0" "$a0" "$c0" "$d0" "$s0" "$u0"
printf "%-22s %6s %9s %9s %7s %11s %9s\n" "--command-playout 1" "$t1" "$a1" "$c1" "$d1" "$s1" "$u1"
grep -q "^server: command playout (up to 0 step(s))" "$OUT/p0-server.log" || fail "p0: the default is not 0 steps"
grep -q "^server: command playout (up to 1 step(s))" "$OUT/p1-server.log" || fail "p1: the server did not take --command-playout 1"
awk -v t="$t0" -v a="$a0" 'BEGIN { exit !(t > 3000 && a < 0.9 * t) }' ||
  fail "without the playout $a0 of $t0 commands answered: the link did not bunch them (the case is not exercised)"
awk -v t0="$t0" -v a0="$a0" -v t1="$t1" -v a1="$a1" 'BEGIN { exit !(t1 > 3000 && t1 - a1 <= (t0 - a0) / 3) }' ||
  fail "with the playout $((t1 - a1)) of $t1 commands unanswered, without it $((t0 - a0)) of $t0: not a third or less"
awk -v s0="$s0" -v s1="$s1" -v d="$d1" 'BEGIN { exit !(s1 <= s0 / 3 && d > 0) }' ||
  fail "with the playout $s1 commands superseded (without it $s0: at most a third), $d1 waited (some must)"
echo "PASS: across a 2 +- 0.6 ms link the playout answered $a1 of $t1 commands (without it $a0 of $t0)"
