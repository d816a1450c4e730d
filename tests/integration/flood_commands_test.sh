#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Issue 15.1: a bounded ToolCommand flood against a seat whose tool 0 is
# owned by station "trainee" (a scripted haptic client holding still in free
# space): new tool ids, garbage for tool 0, and well-formed commands for
# tool 0 from station "mallory". The memory of the server, the trainee's
# haptic client and a viewer (both read ToolCommand) stays flat (a plateau
# within 8 MB each, at most 1.5 MB more in the flood's second half), every
# kind is dropped at the intake gate and counted, the owner's commands are
# applied and the server never falls behind (its own counters:
# flood_commands check).
# usage: flood_commands_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
PART=hardnet/flood
# Under AddressSanitizer freed blocks wait in its quarantine (up to 256 MB)
# before reuse, which grows the resident set with any churn of allocations:
# a small one here, so the bound measures the programs. Its allocator still
# adds ~6 MB under the flood in every process (5.4 MB at 25,000 new ids,
# 5.9 MB at 67,000: a plateau), and up to 10.6 MB with a CPU-bound process
# beside the suite; without the gates 25,000 ids cost 15 MB more, so the
# sanitized bound is 14 MB.
if [ -n "${ASAN_OPTIONS:-}" ]; then
  export ASAN_OPTIONS="$ASAN_OPTIONS:quarantine_size_mb=1" FLOOD_RSS_SLACK_KB=14336
fi
A=0.000,0.004,0.070
printf '# holds still above the kidney\n0 %s\n100 %s\n' "${A//,/ }" "${A//,/ }" > "$OUT/trainee.traj"
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $PART --duration 30 \
  > "$OUT/server.out" 2> "$OUT/server.log" & SRV=$!; PIDS+=("$SRV")
"$BUILD/client/haptic/viscera-haptic" --partition $PART --tool 0 --station trainee --trajectory "$OUT/trainee.traj" \
  --duration 18 --wait-server 20 --quiet > "$OUT/haptic.out" 2> "$OUT/haptic.log" & HAP=$!; PIDS+=("$HAP")
"$BUILD/client/viewer/viscera-viewer" --partition $PART --out "$OUT/frames" --interval-ms 500 --duration 20 \
  > "$OUT/viewer.out" 2> "$OUT/viewer.log" & VIEWER=$!; PIDS+=("$VIEWER")
"$BUILD/client/control/viscera-control" --partition $PART --wait 15 assign 0 trainee > "$OUT/ctl.txt" 2>&1 \
  || fail "assign not applied"
"$BUILD/tests/integration/flood_commands" flood "$VISCERA_DOMAIN" $PART $SRV,$HAP,$VIEWER "${FLOOD_COUNT:-75000}" 5 \
  > "$OUT/flood.out" 2> "$OUT/flood.log" || fail "flood: $(cat "$OUT/flood.out")"
cat "$OUT/flood.out"
wait $HAP || fail "haptic client failed"
wait $VIEWER || fail "viewer failed"
kill -0 $SRV || fail "server died"
kill -INT $SRV; wait $SRV || fail "server exit status"
"$BUILD/tests/integration/flood_commands" check "$OUT/server.out" "$OUT/haptic.out" "$OUT/flood.out" || fail "check"
grep -h "intake gate\|rejected (" "$OUT/server.log" || true
echo PASS
