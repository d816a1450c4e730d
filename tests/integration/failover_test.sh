#!/usr/bin/env bash
# Failures between haptic client and server, with real processes:
# 1. the server is killed (-9) while the probe presses the organ: the haptic
#    client reports "server lost" and renders zero force from then on; when a
#    server comes back it reports "server back" and force returns;
# 2. the haptic client is killed (-9) mid-contact: the server releases the
#    tool and says so. usage: failover_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-15}"
common=(--domain "$DOMAIN" --partition test/failover)
mkdir -p "$OUT"; rm -f "$OUT"/*
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done' EXIT
fail() { echo "FAIL: $*" >&2; tail -n 5 "$OUT"/*.log >&2; exit 1; }
server() { "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" "${common[@]}" >>"$OUT/server.out" 2>>"$OUT/server.log" & SERVER=$!; pids+=($SERVER); }

# Press, hold through the kill, lift after the restart and press again: a
# restarted server never pushes a hand that is already inside (no entry).
cat > "$OUT/press_twice.traj" <<TRAJ
0.0 0.012 0.004 0.070
0.5 0.012 0.004 0.070
1.5 0.012 0.004 0.027
4.6 0.012 0.004 0.027
5.2 0.012 0.004 0.060
6.0 0.012 0.004 0.027
8.0 0.012 0.004 0.027
TRAJ
server
"$BUILD/client/haptic/viscera-haptic" --trajectory "$OUT/press_twice.traj" "${common[@]}" \
  --duration 8 --force-csv "$OUT/force.csv" >"$OUT/haptic.out" 2>"$OUT/haptic.log" & HAPTIC=$!; pids+=($HAPTIC)
sleep 3                 # pressing since t = 1.5 s
kill -9 $SERVER; wait $SERVER 2>/dev/null || true
sleep 1.5
server                  # a new server: the scene restarts from rest
wait $HAPTIC || fail "haptic client failed"
grep -q "server lost" "$OUT/haptic.log" || fail "haptic client did not report the lost server"
grep -q "server back" "$OUT/haptic.log" || fail "haptic client did not report the server's return"
# Force: present before the kill, zero from 0.2 s after it, back after the restart and a new press.
awk -F, 'NR>1 { f=sqrt($5*$5+$6*$6+$7*$7); t=$1;
  if (t>2.0 && t<2.9 && f>0.1) before++;
  if (t>3.2 && t<4.3 && f>0) during++;
  if (t>6.2 && f>0.1) after++ }
  END { printf "ticks with force: before kill %d, 0.2-1.3 s after kill %d, after restart %d\n", before, during, after;
        exit !(before>500 && during==0 && after>1000) }' "$OUT/force.csv" || fail "force did not drop to zero and come back"

# 2. The haptic client vanishes mid-contact: the server releases the tool.
"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/push_hold_kidney.traj" "${common[@]}" \
  >"$OUT/haptic2.out" 2>"$OUT/haptic2.log" & HAPTIC=$!; pids+=($HAPTIC)
sleep 3
kill -9 $HAPTIC; wait $HAPTIC 2>/dev/null || true
sleep 1.5
grep -q "released" "$OUT/server.log" || fail "server did not release the vanished client's tool"
kill -0 $SERVER || fail "server died"
kill -INT $SERVER; wait $SERVER || fail "server exited with an error"
pids=()
echo PASS
