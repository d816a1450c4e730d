#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# deploy/pki.sh run again on a lab's PKI, as lab.sh --one-server --secure
# tells a user whose PKI lacks the group identity ("make the PKI with pki.sh
# ... --server-group K-M"): the identities already handed out (a copy of the
# PKI on another machine, a running instructor's) must still be accepted by
# processes using the new files. Before the fix the rerun made new CAs, and
# the old instructor identity could no longer reach a server started with the
# new PKI. Here: pki.sh OUT --seats 2, a copy of it kept as "the other
# machine's", pki.sh OUT --seats 2 --server-group 1-2; a server of seat 1 with
# the new server-seat01 identity and viscera-control with the copy's
# instructor identity: the pause is applied (exit 0), and the rerun says it
# kept the CAs.
# usage: pki_rerun_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
command -v openssl > /dev/null || fail "openssl missing (deploy/install_deps.sh installs it)"
LO="file://$SRC/deploy/cyclonedds-loopback.xml"
bash "$SRC/deploy/pki.sh" "$OUT/pki" --seats 2 > "$OUT/pki1.log" 2>&1 || fail "pki.sh failed"
# The other machine's copy: its fragments name its own directory.
cp -a "$OUT/pki" "$OUT/copy"
sed -i "s|$OUT/pki/|$OUT/copy/|g" "$OUT"/copy/identities/*/security.xml
bash "$SRC/deploy/pki.sh" "$OUT/pki" --seats 2 --server-group 1-2 > "$OUT/pki2.log" 2>&1 || fail "pki.sh rerun failed"
cat "$OUT/pki2.log"
[ -f "$OUT/pki/identities/server-seat01-02/security.xml" ] || fail "the rerun made no group identity"
CYCLONEDDS_URI="$LO,file://$OUT/pki/identities/server-seat01/security.xml" \
  "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition lab/seat01 \
  > "$OUT/server.log" 2>&1 & SRV=$!; PIDS+=("$SRV")
st=0
CYCLONEDDS_URI="$LO,file://$OUT/copy/identities/instructor/security.xml" \
  "$BUILD/client/control/viscera-control" --partition lab/seat01 --wait 20 pause > "$OUT/control.log" 2>&1 || st=$?
cat "$OUT/control.log"
[ $st = 0 ] || fail "the earlier instructor identity was not accepted by a server with the rerun's identity (exit $st)"
grep -q '^applied: paused' "$OUT/control.log" || fail "the pause was not applied"
grep -q 'server: paused' "$OUT/server.log" || fail "the server did not pause"
kill -INT $SRV; wait $SRV || fail "server exited with an error"
grep -q "kept the existing CAs" "$OUT/pki2.log" || fail "the rerun did not say it kept the CAs"
PIDS=()
echo PASS
