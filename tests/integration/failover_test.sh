#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Failures between haptic client and server, with real processes:
# 1. the server is killed (-9) while the probe presses the organ: the haptic
#    client reports "server lost" and renders zero force from then on; when a
#    server comes back it reports "server back" and force returns;
# 2. the haptic client is killed (-9) mid-contact: the server releases the
#    tool and says so. usage: failover_test.sh BUILD SRC OUT
# Judged by events (log lines, the server's threshold crossings) and the
# client's own ticks (force_check failover), never by wall-clock windows
# (issue 15.6): the steps wait for the events they need.
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-15}"
common=(--domain "$DOMAIN" --partition test/failover)
mkdir -p "$OUT"; rm -f "$OUT"/*
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done' EXIT
fail() { echo "FAIL: $*" >&2; tail -n 5 "$OUT"/*.log >&2; exit 1; }
server() { "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" "${common[@]}" >>"$OUT/server.out" 2>>"$OUT/server.log" & SERVER=$!; pids+=($SERVER); }
# await FILE PATTERN [N]: until FILE holds PATTERN N times (default 1); 60 s at most.
await() { for _ in $(seq 600); do [ "$(grep -c -- "$2" "$1" 2>/dev/null || true)" -ge "${3:-1}" ] && return 0; sleep 0.1; done; return 1; }

# Press, hold through the kill and the restart, lift and press again: a
# restarted server never pushes a hand that is already inside (no entry).
# The hold is long (to 9 s) so that the kill and the restart, which wait
# for events, fall inside it even on a crowded machine.
cat > "$OUT/press_twice.traj" <<TRAJ
0.0 0.012 0.004 0.070
0.5 0.012 0.004 0.070
1.5 0.012 0.004 0.027
9.0 0.012 0.004 0.027
9.6 0.012 0.004 0.060
10.4 0.012 0.004 0.027
13.0 0.012 0.004 0.027
TRAJ
server
"$BUILD/client/haptic/viscera-haptic" --trajectory "$OUT/press_twice.traj" "${common[@]}" \
  --duration 13 --force-csv "$OUT/force.csv" >"$OUT/haptic.out" 2>"$OUT/haptic.log" & HAPTIC=$!; pids+=($HAPTIC)
await "$OUT/server.log" "ST crossed up" || fail "the press never reached the sound threshold"
sleep 0.5               # some pressing
kill -9 $SERVER; wait $SERVER 2>/dev/null || true
await "$OUT/haptic.log" "server lost" || fail "haptic client did not report the lost server"
sleep 1                 # the hand inside, no server
server                  # a new server: the scene restarts from rest
wait $HAPTIC || fail "haptic client failed"
grep -q "server back" "$OUT/haptic.log" || fail "haptic client did not report the server's return"
"$BUILD/tests/integration/force_check" failover "$OUT/force.csv" || fail "force did not drop to zero and come back"

# 2. The haptic client vanishes mid-contact: the server releases the tool.
n0=$(grep -c "ST crossed up" "$OUT/server.log" || true)
"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/push_hold_kidney.traj" "${common[@]}" \
  >"$OUT/haptic2.out" 2>"$OUT/haptic2.log" & HAPTIC=$!; pids+=($HAPTIC)
await "$OUT/server.log" "ST crossed up" $((n0 + 1)) || fail "the second client's press never reached the organ"
kill -9 $HAPTIC; wait $HAPTIC 2>/dev/null || true
await "$OUT/server.log" "released" || fail "server did not release the vanished client's tool"
kill -0 $SERVER || fail "server died"
kill -INT $SERVER; wait $SERVER || fail "server exited with an error"
pids=()
echo PASS
