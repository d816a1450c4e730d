#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# deploy/lab.sh --one-server --secure (issue 17 item 6, the secure variant) on
# loopback: seats 2-3 (--first 2) as threads of one viscera-server holding
# the group identity server-seat02-03 (pki.sh --server-group 2-3, made by
# lab.sh into the test's directory), a scripted trainee and a viewer per seat
# with their own identities, the lab recorder, ended by --duration.
# Asserts: one server process, both seats recorded from their own partition
# and participant with ToolCommands in both, frames and force in both, both
# servers' participants authenticated as CN=server-seat02-03, a recorder
# without identity recorded nothing, each seat re-simulates bit for bit,
# exit 0 with nothing left. Then what the group identity may not do: a
# server holding it for seats 1-3 serves 2 and 3 and is refused seat 1 by
# DDS Security (exit 1, "Not Allowed By Security", the identity and the
# partition named); and a lab whose PKI
# lacks the group identity names it and the pki.sh command that makes it.
# usage: lab_one_server_secure_test.sh BUILD SRC OUT
set -euo pipefail
# shellcheck source=prelude.sh
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
# shellcheck source=lab_checks.sh
. "$(dirname "$0")/lab_checks.sh"
FAIL_LOGS="$OUT/*.out $OUT/l/*.log"
# lab.sh stops what it started on SIGTERM (prelude's cleanup would kill -9 it alone)
cleanup() { for p in "${PIDS[@]}"; do kill -TERM "$p" 2>/dev/null || true; done; }
command -v sqlite3 > /dev/null || fail "sqlite3 missing (deploy/install_deps.sh installs it)"
command -v openssl > /dev/null || fail "openssl missing (deploy/install_deps.sh installs it)"

DURATION=13
launch_lab L "$OUT/lab.out" --out "$OUT/l" --one-server --secure --first 2 --seats 2 --trainees --viewers 1 \
  --duration $DURATION
PIDS+=("$L")
"$BUILD/client/recorder/viscera-recorder" --partition 'lab/*' --out "$OUT/plain.db" --duration $((DURATION - 1)) \
  --quiet > "$OUT/plain_recorder.log" 2>&1 &
PLAIN=$!
PIDS+=("$PLAIN")
wait_trainees "$L" "the lab" "$OUT"/l/seat02-haptic.log "$OUT"/l/seat03-haptic.log
servers=$(ps -o args= -s "$L" | grep -c '^[^ ]*/viscera-server ' || true)
[ "$servers" = 1 ] || fail "$servers server processes in the lab, expected one for both seats"
for ((t = 0; t < (DURATION + 40) * 10; t++)); do kill -0 "$L" 2>/dev/null || break; sleep 0.1; done
kill -0 "$L" 2>/dev/null && fail "lab.sh still running 40 s after its --duration"
st=0; wait "$L" || st=$?
cat "$OUT/lab.out"
[ "$st" = 0 ] || fail "lab.sh --one-server --secure exited with $st"
grep -q "secure=1" "$OUT/lab.out" || fail "lab.sh did not run secure"
expect_nothing_left "$L" "lab.sh --one-server --secure"
wait "$PLAIN" || fail "the unauthenticated recorder failed"
PIDS=()
grep -q "server-seat02-03" "$OUT/l/pki/permissions.xml" || fail "lab.sh made no group identity for seats 2-3"

DB="$OUT/l/lab.db"
expect_lab_recorded "$DB" 2 3 02 03
plain_n=$(sqlite3 "$OUT/plain.db" "SELECT count(*) FROM samples")
[ "$plain_n" = 0 ] || fail "a recorder without identity recorded $plain_n samples of the secure lab"
"$BUILD/client/recorder/viscera-recinfo" "$DB" > "$OUT/recinfo.out" || fail "viscera-recinfo failed on the lab's recording"
subjects=$(grep -A1 '^server ' "$OUT/recinfo.out" | grep -c 'subject: CN=server-seat02-03,' || true)
[ "$subjects" = 2 ] || fail "$subjects server participants authenticated as server-seat02-03, expected 2: $(cat "$OUT/recinfo.out")"
for s in seat02 seat03; do
  expect_frames "$OUT/l/$s-frames1"
  expect_trainee_force "$OUT/l/$s-haptic.log"
  grep -q '^SUMMARY steps=[0-9]' "$OUT/l/$s-server.log" || fail "no SUMMARY line in $s-server.log"
  "$BUILD/server/viscera-resim" "$DB" --quiet --partition "lab/$s" > "$OUT/resim_$s.out" 2>&1 ||
    fail "viscera-resim --partition lab/$s failed: $(tail -3 "$OUT/resim_$s.out")"
  grep -q '^RESIM PASS .*bit_exact=1' "$OUT/resim_$s.out" || fail "lab/$s not re-simulated bit for bit"
done
expect_logs "$OUT/l" recorder seats-server seat02-viewer1 seat02-haptic seat03-viewer1 seat03-haptic

# The group identity is the server's role in seats 2 and 3 only.
PKI="$OUT/l/pki"
rc=0
CYCLONEDDS_URI="file://$SRC/deploy/cyclonedds-loopback.xml,file://$PKI/identities/server-seat02-03/security.xml" \
  "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition lab --seats 3 --first-seat 1 \
  --duration 2 > "$OUT/outside.out" 2> "$OUT/outside.log" || rc=$?
[ "$rc" = 1 ] || fail "a server holding server-seat02-03 for seats 1-3 exited $rc, not 1"
grep -q "seat 'lab/seat01': .*Not Allowed By Security: identity 'CN=server-seat02-03,O=viscera,C=NL' may not serve partition 'lab/seat01'" \
  "$OUT/outside.log" || fail "seat01 was not refused by DDS Security, naming the identity: $(grep -m3 seat01 "$OUT/outside.log")"
for s in 02 03; do
  grep -q "^SEAT partition=lab/seat$s " "$OUT/outside.out" || fail "seat$s did not serve beside the refused seat01"
done

# A PKI made without the group (this lab's, asked for seats 1-3 at once).
launch_lab M "$OUT/lab13.out" --out "$OUT/l13" --pki "$PKI" --one-server --secure --first 1 --seats 3 --duration 30
PIDS+=("$M")
for ((t = 0; t < 300; t++)); do kill -0 "$M" 2>/dev/null || break; sleep 0.1; done
st=0; wait "$M" || st=$?
PIDS=()
cat "$OUT/lab13.out"
[ "$st" = 1 ] || fail "lab.sh with the group identity missing from the PKI exited with $st, expected 1"
grep -q "no identity 'server-seat01-03' in $PKI (make the PKI with pki.sh --seats 3 --prefix lab --server-group 1-3;" \
  "$OUT/lab13.out" || fail "the missing group identity and the pki.sh command were not named"
expect_nothing_left "$M" "lab.sh stopped by an error"
echo PASS
