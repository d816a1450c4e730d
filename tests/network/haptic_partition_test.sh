#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Partition and heal, the trainee's hand (issue 14 item 6): the server in
# site a, a scripted trainee in site b pressing the kidney 8 mm and holding;
# the link goes down for 5 s (longer than the 4 s participant lease of
# cyclonedds-site.xml: both sides lose each other and rediscover) and comes
# back, at two link settings. Judged from the client's log lines (stamped
# with its force log's time) and its force log:
#   - "server lost" during the partition, and the force zero from that tick
#     until "server back",
#   - after "server back" the force ramps back to the tissue's (the server
#     kept its scene; the tool it released keeps its god-object's contact):
#     within 30 % of the force before the partition, within 5 s of the
#     return (rediscovery on a loaded machine may take a few seconds more
#     than the first feedback),
#   - no one-tick change above 0.1 N except the cut.
# usage: haptic_partition_test.sh BUILD SRC OUT
set -euo pipefail
source "$2/tests/network/prelude.sh"
net_sites hp3
export CYCLONEDDS_URI="file://$SRC/deploy/cyclonedds-site.xml"
# The site file without DDS Security: every program refuses it unless told (issue 14 item 5).
export VISCERA_INSECURE=1
SEAT=hp/part
TRAJ="$OUT/press_hold.traj"
printf '%s\n' "0.0 0.012 0.004 0.070" "0.5 0.012 0.004 0.070" "1.5 0.012 0.004 0.027" "40.0 0.012 0.004 0.027" > "$TRAJ"
line_t() { sed -n "s/^haptic: t=\\([0-9.]*\\) s $2.*/\\1/p" "$1" | awk -v a="$3" '$1 > a { print; exit }'; }

partition() { # partition NAME EMULATOR-OPTIONS...
  local n="$1" srv hap i
  shift
  # Down from 10 s after the emulator starts: the client is pressing by then
  # however long discovery took.
  link_start --duration 60 --seed 17 --down 10:5 "$@" || fail "$n: emulator did not start"
  run_in_site a "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $SEAT \
    > "$OUT/$n-server.out" 2> "$OUT/$n-server.log" &
  srv=$!; PIDS+=("$srv")
  run_in_site b timeout 60 "$BUILD/client/haptic/viscera-haptic" --trajectory "$TRAJ" --partition $SEAT \
    --wait-server 15 --duration 40 --force-csv "$OUT/$n-force.csv" > "$OUT/$n-haptic.out" 2> "$OUT/$n-haptic.log" &
  hap=$!; PIDS+=("$hap")
  # Until the client is back after the partition (at most 40 s), then 6 s more.
  for ((i = 0; i < 800; i++)); do
    [ -n "$(line_t "$OUT/$n-haptic.log" "server back" 2.0)" ] && break
    sleep 0.05
  done
  sleep 6
  kill -INT "$hap"; wait "$hap" || fail "$n: haptic client failed"
  kill -INT "$srv"; wait "$srv" || fail "$n: server exited with an error"
  link_stop > "$OUT/$n-link.txt"
  [ "$(link_count 'a->b' down)" -gt 0 ] || fail "$n: the link was never cut"
  local lost back cuts
  # The partition's loss: the first "server lost" whose "server back" came
  # 3 s or more later (a loaded machine may show a short lapse besides).
  read -r lost back < <(sed -n 's/^haptic: t=\([0-9.]*\) s server \(lost\|back\).*/\1 \2/p' "$OUT/$n-haptic.log" |
    awk '$2 == "lost" && !l { l = $1 } $2 == "back" && l { if ($1 - l >= 3) { print l, $1; exit } l = 0 }') || true
  [ -n "${lost:-}" ] && [ -n "${back:-}" ] || fail "$n: no 'server lost' and 'server back' 3 s or more apart (the partition)"
  cuts=$(sed -n 's/^haptic: t=\([0-9.]*\) s server lost.*/\1/p' "$OUT/$n-haptic.log" | tr '\n' ' ')
  local before
  # The force before the partition: the median over the hold up to 0.3 s before the loss.
  before=$(awk -F, -v lost="$lost" 'NR > 1 && $1 > 2.3 && $1 < lost - 0.3 { printf "%.5f\n", sqrt($5*$5 + $6*$6 + $7*$7) }' \
    "$OUT/$n-force.csv" | sort -n | awk '{ a[NR] = $1 } END { print NR ? a[int((NR + 1) / 2)] : -1 }')
  # Through the partition: zero force, but for the ticks the loop runs
  # before it sees the listener's "lost" (at most a few on a starved
  # machine: 1-4 seen with a CPU-bound process beside the suite).
  awk -F, -v lost="$lost" -v back="$back" -v cuts="$cuts" -v n="$n" -v m0="$before" '
    function near_cut(t,   i) { for (i = 1; i <= nc; i++) if (t >= c[i] - 0.002 && t <= c[i] + 0.01) return 1; return 0 }
    function med(a, k,   i, j, x) { for (i = 2; i <= k; i++) { x = a[i]; for (j = i - 1; j >= 1 && a[j] > x; j--) a[j + 1] = a[j]; a[j + 1] = x }
                                    return k ? a[int((k + 1) / 2)] : -1 }
    BEGIN { nc = split(cuts, c, " ") }
    NR > 1 { f = sqrt($5*$5 + $6*$6 + $7*$7); t = $1
      if (t >= lost && t < back) { inside++; if (f > 0) during++ }
      if (t > back && t < back + 5 && !ret && f >= 0.7 * m0) ret = t
      if (ret && t > ret && t < ret + 0.5) b1[++n1] = f
      if (t > 2.0 && !near_cut(t) && $10 > 0.1 + 1e-6) big++ }
    END { m1 = med(b1, n1)
      printf "%s: force %.3f N before, lost at t=%.3f s, %d of %d ticks with force until back at t=%.3f s, back to %.3f N %.3f s after (median over 0.5 s); %d steps > 0.1 N outside the cut\n", n, m0, lost, during, inside, back, m1, ret ? ret - back : -1, big
      exit !(m0 > 0.3 && back - lost > 3 && during <= 5 && ret && m1 > 0.7 * m0 && m1 < 1.3 * m0 && big == 0) }' \
    "$OUT/$n-force.csv" || fail "$n: the force did not stay zero through the partition and ramp back to the tissue's"
}

partition p25 --delay 25 --jitter 5 --no-reorder --loss 2
partition p50 --delay 50 --jitter 10 --no-reorder --loss 5
echo PASS
