#!/usr/bin/env bash
# Short blips while the hand is inside the kidney (issue 14 item 6), real
# processes on loopback, judged from the haptic client's force log (CSV:
# t,x,y,z,fx,fy,fz,in_contact,energy_j,step_n), its log lines (stamped with
# the CSV's time) and its CONTACT counters:
# 1. the server is stopped (SIGSTOP) for 0.4 s during the hold: the client
#    cuts the force when the server's liveliness lapses, says "server lost",
#    and once the server is back ramps the force back to the tissue's (the
#    scene was kept: no restart);
# 2. the client is stopped for 0.4 s during the hold: the server takes it
#    for lost and releases the tool (a false "client lost": the client is
#    alive), and when the client is back the tool's god-object still holds
#    its contact, so the hand 8 mm inside feels the tissue again instead of
#    nothing until it has left the organ.
# No one-tick change above 0.1 N except the cut itself.
# usage: blip_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-223}"
common=(--domain "$DOMAIN" --partition test/hp-blip)
mkdir -p "$OUT"; rm -f "$OUT"/*
pids=()
trap 'for p in "${pids[@]}"; do kill -CONT "$p" 2>/dev/null || true; kill -9 "$p" 2>/dev/null || true; done' EXIT
fail() { echo "FAIL: $*" >&2; tail -n 12 "$OUT"/*.log >&2; exit 1; }
wait_for() { # file pattern seconds
  for _ in $(seq 1 $(($3 * 20))); do grep -q "$2" "$1" 2>/dev/null && return 0; sleep 0.05; done; return 1; }

cat > "$OUT/press_hold.traj" <<TRAJ
0.0 0.012 0.004 0.070
0.5 0.012 0.004 0.070
1.5 0.012 0.004 0.027
9.0 0.012 0.004 0.027
10.0 0.012 0.004 0.070
TRAJ
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" "${common[@]}" \
  >"$OUT/server.out" 2>"$OUT/server.log" & SERVER=$!; pids+=($SERVER)
"$BUILD/client/haptic/viscera-haptic" --trajectory "$OUT/press_hold.traj" "${common[@]}" \
  --force-csv "$OUT/force.csv" >"$OUT/haptic.out" 2>"$OUT/haptic.log" & HAP=$!; pids+=($HAP)
wait_for "$OUT/haptic.log" "driving tool" 10 || fail "haptic client never saw the scene"
sleep 3.5                                   # pressing since t = 1.5 s
kill -STOP $SERVER; sleep 0.4; kill -CONT $SERVER
sleep 2
kill -STOP $HAP; sleep 0.4; kill -CONT $HAP
wait $HAP || fail "haptic client failed"
kill -0 $SERVER || fail "server died"
kill -INT $SERVER; wait $SERVER || fail "server exited with an error"

# 1. The server's stall, from the client's own lines.
# (A loaded machine may also show a lapse at start, before any contact: the
# first loss during the hold is the stall's.)
t_lost=$(sed -n 's/^haptic: t=\([0-9.]*\) s server lost.*/\1/p' "$OUT/haptic.log" | awk '$1 > 2.0 { print; exit }')
t_back=$(sed -n 's/^haptic: t=\([0-9.]*\) s server back.*/\1/p' "$OUT/haptic.log" |
  awk -v l="${t_lost:-0}" '$1 > l { print; exit }')
[ -n "$t_lost" ] && [ -n "$t_back" ] || fail "the client did not report the stalled server lost and back"
awk -v a="$t_lost" -v b="$t_back" 'BEGIN { exit !(a > 2.0 && b > a && b < 9) }' \
  || fail "server lost at t=$t_lost s, back at t=$t_back s: not during the hold"
# 2. The client's own stall: the first gap of >= 0.3 s between ticks during the hold.
t_gap=$(awk -F, 'NR > 2 && p > 2.0 && $1 - p >= 0.3 { print p; exit } { p = $1 }' "$OUT/force.csv")
t_res=$(awk -F, 'NR > 2 && p > 2.0 && $1 - p >= 0.3 { print $1; exit } { p = $1 }' "$OUT/force.csv")
[ -n "$t_gap" ] || fail "no 0.3 s gap in the client's force log: the client was not stalled"
grep -q "tool 0: haptic client lost\|no commands for" "$OUT/server.log" \
  || echo "note: the server did not take the stalled client for lost this time (it answered within the lease)"

# Every cut the client made (a "server lost" line), which may step to zero.
cuts=$(sed -n 's/^haptic: t=\([0-9.]*\) s server lost.*/\1/p' "$OUT/haptic.log" | tr '\n' ' ')
awk -F, -v lost="$t_lost" -v back="$t_back" -v gap="$t_gap" -v res="$t_res" -v cuts="$cuts" '
  function near_cut(t,   i) { for (i = 1; i <= nc; i++) if (t >= c[i] - 0.002 && t <= c[i] + 0.01) return 1; return 0 }
  BEGIN { nc = split(cuts, c, " ") }
  function med(a, n,   i, j, x) { for (i = 2; i <= n; i++) { x = a[i]; for (j = i - 1; j >= 1 && a[j] > x; j--) a[j + 1] = a[j]; a[j + 1] = x }
                                  return n ? a[int((n + 1) / 2)] : -1 }
  NR > 1 { f = sqrt($5*$5 + $6*$6 + $7*$7); t = $1
    if (t > 2.3 && t < lost - 0.05) b0[++n0] = f
    if (t > lost && t < lost + 0.002 + 0.002) cut_seen = cut_seen || (f == 0)
    if (t > lost + 0.01 && t < back - 0.01 && f > 0) during++
    if (t > back + 0.3 && t < back + 0.8) b1[++n1] = f
    if (t > gap - 0.6 && t < gap) b2[++n2] = f
    if (t > res + 0.3 && t < res + 0.8) b3[++n3] = f
    if (t > 2.0 && !near_cut(t) && $10 > 0.1 + 1e-6) { big++; if (!bt) bt = t }
  }
  END { m0 = med(b0, n0); m1 = med(b1, n1); m2 = med(b2, n2); m3 = med(b3, n3)
    printf "server stall: force %.3f N before, %d ticks with force while lost, %.3f N 0.3-0.8 s after back (t %.3f -> %.3f)\n", m0, during, m1, lost, back
    printf "client stall: force %.3f N before, %.3f N 0.3-0.8 s after (gap t %.3f -> %.3f); one-tick changes > 0.1 N outside the cut: %d (first t %s)\n", m2, m3, gap, res, big, bt
    ok = m0 > 0.3 && during == 0 && m1 > 0.7 * m0 && m1 < 1.3 * m0 && m2 > 0.3 && m3 > 0.7 * m2 && m3 < 1.3 * m2 && big == 0
    exit !ok }' "$OUT/force.csv" || fail "force did not come back to the tissue's after a blip (or stepped)"
grep -q '^CONTACT .*server_lost=[1-9]' "$OUT/haptic.out" || fail "CONTACT does not count the server loss"
step=$(sed -n 's/^CONTACT .*step_max_n=\([0-9.]*\).*/\1/p' "$OUT/haptic.out")
awk -v s="$step" 'BEGIN { exit !(s <= 0.1) }' || fail "largest one-tick change $step N > 0.1 N"
grep "contact under delay" "$OUT/haptic.log"
