#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Palpation across an emulated site link (issue 14 items 3 and 7): the
# server in site a, a scripted trainee at 1 kHz in site b on
# deploy/cyclonedds-site.xml, at 0, 25, 50 and 100 ms one way with jitter
# and loss. The hand presses the kidney 8 mm, holds, lets go; its path is a
# hand's (smoothstep between the points of palpate_kidney.traj, velocity
# continuous). Judged from the client's own SUMMARY and force log:
#   - peak force within 10 % of the 0 ms run's (the same trajectory),
#   - no one-tick change above 0.1 N (step_n column, step_max_n),
#   - the passivity observer's energy never above the late-model credit
#     (excess_max_j <= 0, client/haptic/passivity.h; when the client's own
#     loop stalled past the controller's 20 ms reserve, the work over those
#     ticks is counted apart and the rest must be <= 0:
#     energy_max_unstalled_j),
#   - no "server lost" (server_lost=0): the leases hold under the link.
# Needs tests/network/sites.sh and prelude.sh (the two-site harness).
# usage: haptic_palpation_test.sh BUILD SRC OUT
set -euo pipefail
source "$2/tests/network/prelude.sh"
net_sites hp1
export CYCLONEDDS_URI="file://$SRC/deploy/cyclonedds-site.xml"
# The site file without DDS Security: every program refuses it unless told (issue 14 item 5).
export VISCERA_INSECURE=1
SEAT=hp/palp
TRAJ="$OUT/palpate_smooth.traj"
smooth_press "$TRAJ"

palpate() { net_press "$1" 60 5 "$TRAJ" "${@:2}"; } # palpate NAME EMULATOR-OPTIONS... (prelude.sh)

palpate d0 --delay 0
ref=$(field "$OUT/d0-haptic.out" peak_force)
awk -v f="${ref:-0}" 'BEGIN { exit !(f > 0.5) }' || fail "0 ms: peak force $ref N: no contact"
printf "%-28s %8s %7s %8s %11s %6s %9s\n" link peak_N err_% step_N energy_J lost latency
for setting in "d0:--delay 0" "d25:--delay 25 --jitter 5 --no-reorder --loss 2" \
  "d50:--delay 50 --jitter 10 --no-reorder --loss 5" "d100:--delay 100 --jitter 10 --no-reorder --loss 10"; do
  name="${setting%%:*}" opts="${setting#*:}"
  # shellcheck disable=SC2086
  [ "$name" = d0 ] || palpate "$name" $opts
  o="$OUT/$name-haptic.out"
  peak=$(field "$o" peak_force) step=$(field "$o" step_max_n) en=$(field "$o" excess_max_j)
  lost=$(field "$o" server_lost) lat=$(field "$o" latency_us_median)
  err=$(awk -v p="$peak" -v r="$ref" 'BEGIN { printf "%.1f", 100 * (p - r) / r }')
  printf "%-28s %8.3f %7s %8.4f %11.3g %6s %7.0f ms\n" "$opts" "$peak" "$err" "$step" "$en" "$lost" \
    "$(awk -v l="$lat" 'BEGIN { print l / 1000 }')"
  # When the first contact sample reached the client only after the hand
  # had stopped (2.0 s; a loaded machine stalled the feedback), the force
  # still ramps in on the resting hand: the late-model credit (before it,
  # the controller withheld it: 0 N).
  first=$(awk -F, 'NR > 1 && $8 == 1 { print $1; exit }' "$OUT/$name-force.csv")
  if awk -v t="${first:-0}" 'BEGIN { exit !(t >= 2.0) }'; then
    echo "note: the first contact sample arrived at $first s, after the hand stopped (2.0 s): credited $(field "$o" credit_j) J"
  fi
  awk -v p="$peak" -v r="$ref" 'BEGIN { exit !(p >= 0.9 * r && p <= 1.1 * r) }' || fail "$opts: peak $peak N vs $ref N"
  awk -v s="$step" 'BEGIN { exit !(s <= 0.1) }' || fail "$opts: one-tick change $step N"
  # The controller budgets the whole rate-limited release of the force
  # before it renders it (client/haptic/passivity.h); before it did, a hand
  # that accelerated away left 5-54 uJ here under load.
  # A tick of the client's own loop longer than the controller's 20 ms
  # reserve (a loaded machine descheduled it: seen 0.4-0.8 s at load 14)
  # holds the force while the scripted hand moves on; the client counts that
  # work apart (stall_energy_j), and the rest must still be <= 0.
  if ! awk -v e="$en" 'BEGIN { exit !(e <= 0) }'; then
    st=$(field "$o" stall_ticks) se=$(field "$o" stall_energy_j) eu=$(field "$o" energy_max_unstalled_j)
    awk -v s="${st:-0}" -v u="${eu:-1}" 'BEGIN { exit !(s > 0 && u <= 0) }' \
      || fail "$opts: passivity observer at $en J (stalled ticks ${st:-?}, ${se:-?} J in them, ${eu:-?} J without)"
    echo "note: observer at $en J, all of it over $st stalled tick(s) of the client's loop ($se J); without them $eu J (machine load)"
  fi
  stall=$(server_stall_us "$OUT/$name-server.log") cstall=$(client_stall_us "$OUT/$name-haptic.log")
  if [ "$lost" != 0 ]; then
    awk -v s="${stall:-0}" -v c="${cstall:-0}" 'BEGIN { exit !(s > 150000 || c > 100000) }' \
      || fail "$opts: $lost false 'server lost' (server's longest step ${stall} us, client's tick ${cstall} us)"
    echo "note: 'server lost' $lost times with the server's longest step ${stall} us, the client's longest tick ${cstall} us (machine load)"
  fi
done
echo PASS
