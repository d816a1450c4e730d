#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The secure seat across the link (issue 14): a PKI from deploy/pki.sh; the
# server with identity server-seat01 in site a; in site b the trainee
# (trainee-seat01), a recorder with the 'recorder' identity and one without
# any identity; deploy/cyclonedds-site.xml plus each identity's fragment. At
# two link settings (25 ms, 2 % loss; 50 +- 10 ms with reordering, 5 % loss):
# authentication and key exchange complete over the lossy link, the trainee
# feels the kidney, the authenticated recorder records the trainee's commands
# and the unauthenticated one records nothing. usage: secure_seat_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
command -v openssl >/dev/null || { echo "SKIP: openssl missing (deploy/install_deps.sh installs it)"; exit 77; }
net_sites lk4
# A hand's press (prelude.sh): still pressing when contact reaches the client over the link.
smooth_press "$OUT/press.traj"
SITE="file://$SRC/deploy/cyclonedds-site.xml"
bash "$SRC/deploy/pki.sh" "$OUT/pki" --seats 1 --prefix lk > "$OUT/pki.txt" 2>&1 || fail "pki.sh failed"
as() { echo "$SITE,file://$OUT/pki/identities/$1/security.xml"; }
SEAT=lk/seat01
INFO="$BUILD/client/recorder/viscera-recinfo"

secure() { # secure NAME EMULATOR-OPTIONS...
  local n="$1" srv rs rp peak secure_n plain_n
  shift
  link_start --duration 60 --seed 17 "$@" || fail "$n: emulator did not start"
  CYCLONEDDS_URI="$(as server-seat01)" run_in_site a "$BUILD/server/viscera-server" \
    --scene "$SRC/assets/scenes/default.yaml" --partition $SEAT > "$OUT/$n-server.out" 2> "$OUT/$n-server.log" &
  srv=$!; PIDS+=("$srv")
  CYCLONEDDS_URI="$(as recorder)" run_in_site b "$BUILD/client/recorder/viscera-recorder" --partition 'lk/*' \
    --out "$OUT/$n-secure.db" --quiet > "$OUT/$n-rec-secure.log" 2>&1 &
  rs=$!; PIDS+=("$rs")
  # The eavesdropper: no identity, so it must say --insecure to start at all.
  CYCLONEDDS_URI="$SITE" run_in_site b "$BUILD/client/recorder/viscera-recorder" --insecure --partition $SEAT \
    --out "$OUT/$n-plain.db" --quiet > "$OUT/$n-rec-plain.log" 2>&1 &
  rp=$!; PIDS+=("$rp")
  CYCLONEDDS_URI="$(as trainee-seat01)" run_in_site b timeout 60 "$BUILD/client/haptic/viscera-haptic" \
    --trajectory "$OUT/press.traj" --partition $SEAT --wait-server 20 --quiet \
    > "$OUT/$n-haptic.out" 2> "$OUT/$n-haptic.log" || fail "$n: the secure trainee failed"
  kill -INT "$srv"; wait "$srv" || fail "$n: server exited with an error"
  sleep 1
  kill -INT "$rs" "$rp"; wait "$rs" || fail "$n: secure recorder failed"; wait "$rp" || fail "$n: plain recorder failed"
  PIDS=()
  link_stop > "$OUT/$n-link.txt"
  [ "$(link_count 'a->b' loss)" -gt 0 ] || fail "$n: the link dropped nothing"
  peak=$(field "$OUT/$n-haptic.out" peak_force)
  "$INFO" "$OUT/$n-secure.db" > "$OUT/$n-secure-info.txt" 2>&1 || fail "$n: recinfo on the secure recording failed"
  "$INFO" "$OUT/$n-plain.db" > "$OUT/$n-plain-info.txt" 2>&1 || fail "$n: recinfo on the plain recording failed"
  secure_n=$(sed -n 's/^total: \([0-9]*\) samples.*/\1/p' "$OUT/$n-secure-info.txt")
  plain_n=$(sed -n 's/^total: \([0-9]*\) samples.*/\1/p' "$OUT/$n-plain-info.txt")
  echo "$n: secure trainee peak force ${peak:-none} N; recorded: authenticated ${secure_n:-?}, unauthenticated ${plain_n:-?} samples"
  awk -v f="${peak:-0}" 'BEGIN { exit !(f > 0.3) }' || fail "$n: no contact force over the secure link"
  grep -q viscera_ToolCommand "$OUT/$n-secure-info.txt" || fail "$n: authenticated recorder missed the trainee's commands"
  [ "${secure_n:-0}" -gt 1000 ] || fail "$n: authenticated recorder got too little (${secure_n:-0})"
  [ "${plain_n:-x}" = 0 ] || fail "$n: unauthenticated participant received ${plain_n:-?} samples"
}

secure light --delay 25 --loss 2
secure heavy --delay 50 --jitter 10 --loss 5
echo PASS
