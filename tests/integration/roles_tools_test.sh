#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Tool roles on the server (issue 7), real processes on loopback: a probe
# scene, two scripted haptic clients on tool 0, station alice holding still
# at A and station bob at B (3 cm apart, free space), and the instructor's
# viscera-control. Asserts, from what the server publishes (ToolRole, and
# ContactFeedback's proxy = the server's tool position in free space):
#   start: version 1, any station drives the tool
#   assign 0 alice   -> version 2, owner alice, the tool stays at A
#   takeover 0 bob   -> version 3, guide bob authority 1, the tool at B
#   guide 0 bob 0.5  -> version 4, the tool at the midpoint of A and B
#   release 0        -> version 5, no guide, the tool back at A
#   guide 0 bob 0.5, then bob's client killed -> the tool back at A with
#   alice alone (the guide's side ends, the tool stays with its owner)
#   reset            -> roles kept and published again, the tool at A
#   refusals: bob guiding a tool it owns, a coupling above the tool's
#   stiffness, an unknown tool; and the server counted bob's commands
#   rejected while the tool was alice's alone.
# usage: roles_tools_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
FAIL_TAIL=8 FAIL_LOGS="$OUT/*.txt"
PART=test/roles
# Free space above the default kidney (its top is at z = 0.035 m).
A=0.000,0.004,0.070; B=0.030,0.004,0.070; M=0.015,0.004,0.070
printf '# alice holds still at A\n0 %s\n100 %s\n' "${A//,/ }" "${A//,/ }" > "$OUT/alice.traj"
printf '# bob holds still at B\n0 %s\n100 %s\n' "${B//,/ }" "${B//,/ }" > "$OUT/bob.traj"
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $PART --duration 120 \
  > "$OUT/server.out" 2> "$OUT/server.log" & SRV=$!; PIDS+=($SRV)
HAP=("$BUILD/client/haptic/viscera-haptic" --partition $PART --tool 0 --duration 110 --wait-server 20 --quiet)
"${HAP[@]}" --station alice --trajectory "$OUT/alice.traj" > "$OUT/alice.out" 2> "$OUT/alice.log" & ALICE=$!; PIDS+=($ALICE)
"${HAP[@]}" --station bob --trajectory "$OUT/bob.traj" > "$OUT/bob.out" 2> "$OUT/bob.log" & BOB=$!; PIDS+=($BOB)
CTL=("$BUILD/client/control/viscera-control" --partition $PART --wait 15)
WATCH=("$BUILD/tests/integration/roles_watch" $PART 0 --timeout 25)
step() { # step NAME CONTROL-ARGS... -- WATCH-ARGS...
  local name="$1"; shift; local ctl=()
  while [ "$1" != "--" ]; do ctl+=("$1"); shift; done; shift
  if [ ${#ctl[@]} -gt 0 ]; then "${CTL[@]}" "${ctl[@]}" >> "$OUT/ctl.txt" 2>&1 || fail "$name: not applied"; fi
  echo "== $name" >> "$OUT/watch.txt"
  "${WATCH[@]}" "$@" >> "$OUT/watch.txt" 2>&1 || fail "$name: $(tail -1 "$OUT/watch.txt")"
}
step start -- --version 1 --owner - --guide -
step assign assign 0 alice -- --version 2 --owner alice --guide - --near $A
# bob's commands now count as rejected: wait until the server has said so.
for i in $(seq 100); do grep -q "from station 'bob' rejected: tool assigned to station 'alice'" "$OUT/server.log" && break; sleep 0.1; done
grep -q "from station 'bob' rejected: tool assigned to station 'alice'" "$OUT/server.log" || fail "bob's commands not rejected"
step takeover takeover 0 bob -- --version 3 --owner alice --guide bob --authority 1 --near $B
step guide guide 0 bob 0.5 -- --version 4 --guide bob --authority 0.5 --near $M
step release release 0 -- --version 5 --owner alice --guide - --near $A
# Refusals: the role stays as it was (version 5).
for bad in "guide 0 alice 0.5" "guide 0 bob 0.5 100000" "assign 7 alice"; do
  if "${CTL[@]}" $bad >> "$OUT/ctl.txt" 2>&1; then fail "'$bad' was applied"; fi
done
grep -q "refused: .*station 'alice' owns the tool" "$OUT/ctl.txt" || fail "owner-as-guide not refused with its reason"
grep -q "refused: .*above the tool's stiffness 400 N/m" "$OUT/ctl.txt" || fail "stiff coupling not refused with its reason"
grep -q "refused: .*tool id out of range" "$OUT/ctl.txt" || fail "bad tool id not refused with its reason"
step unchanged -- --version 5 --owner alice --guide - --near $A
# The guide's client dies mid-guidance: its hand stops counting, the tool
# stays with alice (at A), and the role is unchanged (bob may come back).
step guide-again guide 0 bob 0.5 -- --version 6 --near $M
kill -9 $BOB
step guide-lost -- --version 6 --guide bob --near $A
# A reset releases the tools but keeps the roles (published again, same
# version): alice's commands move the tool again, bob's role is still there.
step reset reset -- --version 6 --owner alice --guide bob --near $A
kill -INT $ALICE; kill -INT $SRV
wait $SRV || fail "server exited with an error"
wait $ALICE || true
PIDS=()
cat "$OUT/ctl.txt"
grep -E "^(ROLE|AT|==)" "$OUT/watch.txt"
n=$(sed -n 's/.*tool assigned to another station: \([0-9]*\).*/\1/p' "$OUT/server.log")
echo "commands rejected as not assigned: ${n:-none}"
[ "${n:-0}" -gt 0 ] || fail "the server counted no command rejected for the tool's assignment"
roles=$(sed -n 's/.*viscera_ToolRole=\([0-9]*\).*/\1/p' "$OUT/server.out")
# Once per tool at start, once per change (5), once after the reset; never
# for a refused or unchanged command.
[ "${roles:-0}" -eq 7 ] || fail "ToolRole published ${roles:-0} times, expected 7"
grep "guide client" "$OUT/server.log" || true
echo PASS
