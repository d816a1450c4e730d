#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Issue 16 item 2: a recording names each participant's certificate subject
# when the session runs with DDS Security, verified by the recorder against
# the participant's authenticated GUID (common/dds/vdds_subject.h), and says
# there is none without security.
#   secure: server-seat01, trainee-seat01 (haptic) and the recorder identity
#     from deploy/pki.sh; recinfo shows each subject exactly as openssl reads
#     it from the certificate, and the report's section names the trainee's.
#   plain (beside it, same domain, its own partition): no subject stored,
#     recinfo and the report say so.
# usage: rec_subject_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
NET="${CYCLONEDDS_URI:?loopback config expected in CYCLONEDDS_URI}"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do echo "--- $f"; tail -8 "$f"; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
command -v openssl >/dev/null || fail "openssl missing (deploy/install_deps.sh installs it)"
bash "$SRC/deploy/pki.sh" "$OUT/pki" --seats 1 > "$OUT/pki.log" 2>&1 || fail "pki.sh failed"
as() { echo "$NET,file://$OUT/pki/identities/$1/security.xml"; }
SRV="$BUILD/server/viscera-server"; HAP="$BUILD/client/haptic/viscera-haptic"
REC="$BUILD/client/recorder/viscera-recorder"; INFO="$BUILD/client/recorder/viscera-recinfo"
REPORT="$BUILD/client/report/viscera-report"
SCENE="$SRC/assets/scenes/default.yaml"; TRAJ="$SRC/assets/trajectories/palpate_kidney.traj"
SEAT=lab/seat01 PLAIN=rec_subject/plain

CYCLONEDDS_URI="$(as server-seat01)" "$SRV" --scene "$SCENE" --partition $SEAT --duration 11 \
  > "$OUT/server.log" 2>&1 & PIDS+=($!)
CYCLONEDDS_URI="$(as recorder)" "$REC" --partition 'lab/*' --out "$OUT/secure.db" --duration 9 --quiet \
  > "$OUT/rec_secure.log" 2>&1 & REC_S=$!; PIDS+=($!)
CYCLONEDDS_URI="$NET" "$SRV" --scene "$SCENE" --partition $PLAIN --duration 11 > "$OUT/server_plain.log" 2>&1 & PIDS+=($!)
CYCLONEDDS_URI="$NET" "$REC" --partition $PLAIN --out "$OUT/plain.db" --duration 9 --quiet \
  > "$OUT/rec_plain.log" 2>&1 & REC_P=$!; PIDS+=($!)
sleep 1.5
CYCLONEDDS_URI="$(as trainee-seat01)" "$HAP" --trajectory "$TRAJ" --partition $SEAT --station alice --duration 5 \
  --quiet > "$OUT/haptic.log" 2>&1 & PIDS+=($!)
CYCLONEDDS_URI="$NET" "$HAP" --trajectory "$TRAJ" --partition $PLAIN --station bob --duration 5 --quiet \
  > "$OUT/haptic_plain.log" 2>&1 & PIDS+=($!)
wait $REC_S || fail "secure recorder failed"
wait $REC_P || fail "plain recorder failed"

# Secure: each identity's subject, as openssl reads it from the certificate.
"$INFO" "$OUT/secure.db" > "$OUT/info_secure.log" 2>&1 || fail "recinfo secure.db failed"
for id in trainee-seat01 server-seat01; do
  want="$(openssl x509 -noout -subject -nameopt RFC2253 -in "$OUT/pki/identities/$id/cert.pem" | sed 's/^subject=//')"
  [ -n "$want" ] || fail "cannot read $id's certificate subject"
  grep -qxF "           subject: $want" "$OUT/info_secure.log" || fail "recinfo does not show $id's subject '$want'"
  echo "ok: $id recorded as '$want'"
done
grep -q "^certificate subjects: [2-9], each verified" "$OUT/info_secure.log" || fail "recinfo: no verified subject count"
grep -q " cert=" "$OUT/info_secure.log" && fail "the subject's hex was stored in user data as well"

# The report names the trainee's certificate in its section (CSV and HTML).
"$REPORT" --out "$OUT/report" "$OUT/secure.db" 2> "$OUT/report.log" || fail "viscera-report secure.db failed"
grep -q "station alice (haptic on .* certificate CN=trainee-seat01/O=viscera/C=NL)" "$OUT/report/report.csv" ||
  fail "report.csv: no trainee certificate: $(sed -n 2p "$OUT/report/report.csv" | cut -c1-300)"
grep -q "certificate CN=trainee-seat01/O=viscera/C=NL" "$OUT/report/report.html" || fail "report.html: no trainee certificate"

# Without security: nothing stored, and said so.
"$INFO" "$OUT/plain.db" > "$OUT/info_plain.log" 2>&1 || fail "recinfo plain.db failed"
grep -q "station=bob" "$OUT/info_plain.log" || fail "plain recording lacks the trainee's participant"
grep -q "subject:" "$OUT/info_plain.log" && fail "a subject was stored without security"
grep -q "^certificate subjects: none (the recorder did not run with DDS Security" "$OUT/info_plain.log" ||
  fail "recinfo does not say the plain recording has no subject"
"$REPORT" --out "$OUT/report_plain" "$OUT/plain.db" 2> "$OUT/report_plain.log" || fail "viscera-report plain.db failed"
grep -q "station bob (haptic on .* certificate none: not secure)" "$OUT/report_plain/report.csv" ||
  fail "report.csv (plain) does not say 'not secure': $(sed -n 2p "$OUT/report_plain/report.csv" | cut -c1-300)"
echo "PASS: secure recording names verified subjects; plain recording has none and says so"
