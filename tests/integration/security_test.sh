#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# DDS Security end to end (issue 7): a PKI from deploy/pki.sh, a secure seat
# (server-seat01 + trainee-seat01 haptic client) on loopback, and what the
# other identities may and may not do:
#   1. the secure seat works: the trainee's probe gets contact force;
#   2. an unauthenticated participant (no security config) receives nothing:
#      a plain recorder in the seat's partition records no sample, while a
#      recorder with the 'recorder' identity records the seat (positive control);
#   3. a trainee certificate cannot publish SessionControl (viscera-control
#      cannot create its writer), the instructor's can (answered by the server);
#   4. a trainee certificate cannot publish into another seat (its haptic
#      client is refused in lab/seat02);
#   5. an observer certificate publishes nothing: its SessionControl and its
#      haptic client's ToolCommand are refused;
#   3b. a trainee certificate cannot write the server's topics even when it
#      announces role "server" (the certificate, not the claimed role,
#      decides: issue 15.2).
# usage: security_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
NET="${CYCLONEDDS_URI:?loopback config expected in CYCLONEDDS_URI}"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do echo "--- $f"; tail -8 "$f"; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
command -v openssl >/dev/null || fail "openssl missing (deploy/install_deps.sh installs it)"

bash "$SRC/deploy/pki.sh" "$OUT/pki" --seats 2 > "$OUT/pki.log" 2>&1 || fail "pki.sh failed"
as() { echo "$NET,file://$OUT/pki/identities/$1/security.xml"; }
SRV="$BUILD/server/viscera-server"; HAP="$BUILD/client/haptic/viscera-haptic"
REC="$BUILD/client/recorder/viscera-recorder"; INFO="$BUILD/client/recorder/viscera-recinfo"
CTL="$BUILD/client/control/viscera-control"
SEAT=lab/seat01

CYCLONEDDS_URI="$(as server-seat01)" "$SRV" --scene "$SRC/assets/scenes/default.yaml" --partition $SEAT \
  --duration 14 > "$OUT/server.log" 2>&1 & PIDS+=($!)
CYCLONEDDS_URI="$(as recorder)" "$REC" --partition 'lab/*' --out "$OUT/secure.db" --duration 11 --quiet \
  > "$OUT/rec_secure.log" 2>&1 & PIDS+=($!)
CYCLONEDDS_URI="$NET" "$REC" --partition $SEAT --out "$OUT/plain.db" --duration 11 --quiet \
  > "$OUT/rec_plain.log" 2>&1 & PIDS+=($!)
sleep 1.5
CYCLONEDDS_URI="$(as trainee-seat01)" "$HAP" --trajectory "$SRC/assets/trajectories/palpate_kidney.traj" \
  --partition $SEAT --quiet > "$OUT/haptic.log" 2>&1 & HAP_PID=$!; PIDS+=($HAP_PID)

# 3. SessionControl: the trainee is refused by access control, the instructor is answered.
if CYCLONEDDS_URI="$(as trainee-seat01)" "$CTL" --partition $SEAT --wait 3 pause > "$OUT/ctl_trainee.log" 2>&1; then
  fail "a trainee identity sent SessionControl"
fi
grep -q "Not Allowed By Security" "$OUT/ctl_trainee.log" || fail "trainee SessionControl not refused by access control"
CYCLONEDDS_URI="$(as instructor)" "$CTL" --partition $SEAT --wait 8 thresholds 0 0.5 0.8 1.5 \
  > "$OUT/ctl_instructor.log" 2>&1 || fail "the instructor's SessionControl was not applied"
grep -q "^applied:" "$OUT/ctl_instructor.log" || fail "no 'applied' answer for the instructor"

# 3b. The server's topics (issue 15.2, under --secure): a trainee's certificate
# cannot write them, whatever role it announces: the impostor tool claiming
# role "server" cannot create its writers (ContactFeedback, MeshState,
# MeshDelta).
IMP="$BUILD/tests/integration/impostor"
if [ -x "$IMP" ]; then
  if CYCLONEDDS_URI="$(as trainee-seat01)" "$IMP" run "${VISCERA_DOMAIN:-0}" $SEAT server 1 > "$OUT/impostor_trainee.log" 2>&1; then
    fail "a trainee identity wrote the server's ContactFeedback"
  fi
  grep -q "Not Allowed By Security" "$OUT/impostor_trainee.log" || fail "the trainee's forged feedback was not refused by access control"
fi

# 4. Another seat: the trainee of seat 1 cannot take part in seat 2.
if CYCLONEDDS_URI="$(as trainee-seat01)" timeout 20 "$HAP" --trajectory "$SRC/assets/trajectories/palpate_kidney.traj" \
  --partition lab/seat02 --wait-server 2 --quiet > "$OUT/haptic_seat02.log" 2>&1; then
  fail "trainee-seat01 ran a haptic client in lab/seat02"
fi
grep -q "Not Allowed By Security" "$OUT/haptic_seat02.log" || fail "seat02 not refused by access control"

# 5. An observer only views: refused SessionControl and ToolCommand alike.
if CYCLONEDDS_URI="$(as observer)" "$CTL" --partition $SEAT --wait 3 pause > "$OUT/ctl_observer.log" 2>&1; then
  fail "an observer identity sent SessionControl"
fi
grep -q "Not Allowed By Security" "$OUT/ctl_observer.log" || fail "observer SessionControl not refused by access control"
if CYCLONEDDS_URI="$(as observer)" timeout 20 "$HAP" --trajectory "$SRC/assets/trajectories/palpate_kidney.traj" \
  --partition $SEAT --wait-server 2 --quiet > "$OUT/haptic_observer.log" 2>&1; then
  fail "an observer identity drove a tool"
fi
grep -q "Not Allowed By Security" "$OUT/haptic_observer.log" || fail "observer ToolCommand not refused by access control"

# 1. The secure seat works.
wait $HAP_PID || fail "secure haptic client failed"
peak=$(sed -n 's/.*peak_force=\([0-9.]*\).*/\1/p' "$OUT/haptic.log")
echo "secure seat: peak force ${peak:-none} N"
awk -v f="${peak:-0}" 'BEGIN { exit !(f > 0.3) }' || fail "no contact force over the secure session"

# 2. Recordings: the authenticated recorder has the seat, the unauthenticated one nothing.
for p in "${PIDS[@]}"; do wait "$p" 2>/dev/null || true; done
PIDS=()
"$INFO" "$OUT/secure.db" > "$OUT/secure_info.log" 2>&1 || fail "recinfo on the secure recording failed"
"$INFO" "$OUT/plain.db" > "$OUT/plain_info.log" 2>&1 || fail "recinfo on the plain recording failed"
secure_n=$(sed -n 's/^total: \([0-9]*\) samples.*/\1/p' "$OUT/secure_info.log")
plain_n=$(sed -n 's/^total: \([0-9]*\) samples.*/\1/p' "$OUT/plain_info.log")
echo "samples recorded: authenticated recorder ${secure_n:-?}, unauthenticated ${plain_n:-?}"
grep -q viscera_ToolCommand "$OUT/secure_info.log" || fail "authenticated recorder missed the trainee's commands"
[ "${secure_n:-0}" -gt 1000 ] || fail "authenticated recorder got too little (${secure_n:-0})"
[ "${plain_n:-x}" = 0 ] || fail "unauthenticated participant received ${plain_n:-?} samples"
echo PASS
