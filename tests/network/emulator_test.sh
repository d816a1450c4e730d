#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# link_emu itself (issue 14), with numbered UDP datagrams (udp_probe) from
# site a to site b, 2 ms apart (the sites carry no other frame: no IPv6, static
# neighbours):
#   - seeded: 30 % loss with seed 5 twice drops the same datagrams and prints
#     the same counts; seed 6 drops others; the loss is 20-40 %;
#   - jitter (20 +- 15 ms) reorders datagrams and says so; with --no-reorder
#     the same jitter delivers them in order;
#   - duplication: 10 % more datagrams arrive than were sent, as counted;
#   - bursty loss (Gilbert-Elliott 5,20,90): losses come in runs (mean run
#     longer than with random loss at the same rate);
#   - a link cut (--down 1.0:0.4) drops one run of datagrams (about 200 at
#     500/s), all counted as cut, and nothing else;
#   - a rate limit (800 kbit/s against 4 Mbit/s offered) drops at the queue
#     and delivers fewer bytes than were offered.
# usage: emulator_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
net_sites lk7
PROBE="$BUILD/tests/network/udp_probe"
N=500

probe() { # probe NAME SIZE EMULATOR-OPTIONS...: OUT/NAME.rx has the numbers received, in order
  local n="$1" size="$2" rx count="${PROBE_N:-$N}"
  shift 2
  link_start --duration 30 "$@" || fail "$n: emulator did not start"
  run_in_site b "$PROBE" recv 9000 800 > "$OUT/$n.rx" 2> "$OUT/$n-recv.log" &
  rx=$!; PIDS+=("$rx")
  sleep 0.3
  run_in_site a "$PROBE" send "$SITE_B_ADDR" 9000 "$count" 2000 "$size" || fail "$n: sender failed"
  wait "$rx" || fail "$n: receiver failed"
  link_stop > "$OUT/$n.link"
  PIDS=()
  echo "$n: $(wc -l < "$OUT/$n.rx") of $count received; $(head -1 "$OUT/$n.link")"
}
inversions() { awk 'NR > 1 && $1 < p { n++ } { p = $1 } END { print n + 0 }' "$1"; }
# mean length of the runs of missing numbers (of ${PROBE_N:-N} sent)
mean_run() { sort -n -u "$1" | awk -v n="${PROBE_N:-$N}" '{ if ($1 > p + 1) { runs++; lost += $1 - p - 1 } p = $1 }
  BEGIN { p = -1 } END { if (n - 1 > p) { runs++; lost += n - 1 - p } printf "%.2f", runs ? lost / runs : 0 }'; }
count() { sed -n "s/^link $2: .* $3=\([0-9]*\).*/\1/p; s/^link $2: $3=\([0-9]*\).*/\1/p" "$OUT/$1.link"; }

probe s5a 100 --seed 5 --loss 30
probe s5b 100 --seed 5 --loss 30
probe s6 100 --seed 6 --loss 30
cmp -s "$OUT/s5a.rx" "$OUT/s5b.rx" || fail "the same seed dropped different datagrams"
[ "$(head -1 "$OUT/s5a.link")" = "$(head -1 "$OUT/s5b.link")" ] || fail "the same seed gave different counts"
cmp -s "$OUT/s5a.rx" "$OUT/s6.rx" && fail "seeds 5 and 6 dropped the same datagrams"
got=$(wc -l < "$OUT/s5a.rx")
[ "$got" -ge $((N * 60 / 100)) ] && [ "$got" -le $((N * 80 / 100)) ] || fail "30 % loss delivered $got of $N"
[ "$(count s5a 'a->b' loss)" = $((N - got)) ] || fail "loss count $(count s5a 'a->b' loss) != $((N - got)) missing"

probe reorder 100 --seed 7 --delay 20 --jitter 15
probe inorder 100 --seed 7 --delay 20 --jitter 15 --no-reorder
[ "$(inversions "$OUT/reorder.rx")" -gt 10 ] || fail "jitter did not reorder ($(inversions "$OUT/reorder.rx") inversions)"
[ "$(count reorder 'a->b' reordered)" -gt 10 ] || fail "the emulator did not count reordering"
[ "$(inversions "$OUT/inorder.rx")" = 0 ] || fail "--no-reorder delivered $(inversions "$OUT/inorder.rx") out of order"
[ "$(wc -l < "$OUT/inorder.rx")" = $N ] || fail "--no-reorder lost datagrams"

probe dup 100 --seed 8 --dup 10
d=$(count dup 'a->b' duplicated); got=$(wc -l < "$OUT/dup.rx")
[ "$got" = $((N + d)) ] && [ "$d" -ge $((N * 5 / 100)) ] && [ "$d" -le $((N * 15 / 100)) ] \
  || fail "10 % duplication: $got received, $d duplicated"

probe burst 100 --seed 9 --burst 5,20,90
probe random 100 --seed 9 --loss "$(awk -v g="$(wc -l < "$OUT/burst.rx")" -v n=$N 'BEGIN { printf "%.1f", 100 * (n - g) / n }')"
echo "mean run of lost datagrams: bursty $(mean_run "$OUT/burst.rx"), random $(mean_run "$OUT/random.rx")"
awk -v b="$(mean_run "$OUT/burst.rx")" -v r="$(mean_run "$OUT/random.rx")" 'BEGIN { exit !(b > 2 && b > 1.5 * r) }' \
  || fail "Gilbert-Elliott loss is not bursty"

# The cut is timed from the emulator's start; 2 s of datagrams cover it even
# when a loaded machine starts the sender late.
PROBE_N=1000 probe down 100 --seed 10 --down 1.0:0.4
cut=$(count down 'a->b' down)
# About 200 at 500/s; a sender that stalled and catches up may put more or fewer in the window.
awk -v m="$cut" 'BEGIN { exit !(m >= 50 && m <= 600) }' || fail "a 0.4 s cut at 500 datagrams/s dropped $cut"
[ "$(count down 'a->b' loss)" = 0 ] && [ "$(wc -l < "$OUT/down.rx")" = $((1000 - cut)) ] || fail "the cut lost more than it counted"
awk -v r="$(PROBE_N=1000 mean_run "$OUT/down.rx")" -v m="$cut" 'BEGIN { exit !(r == m) }' \
  || fail "the cut is not one run ($(PROBE_N=1000 mean_run "$OUT/down.rx") against $cut)"

probe rate 1000 --seed 11 --rate 800 --queue 20000
[ "$(count rate 'a->b' queue)" -gt 0 ] || fail "4 Mbit/s into 800 kbit/s dropped nothing at the queue"
[ "$(wc -l < "$OUT/rate.rx")" -lt $N ] || fail "the rate limit delivered everything"
echo PASS
