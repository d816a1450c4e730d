#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# "Nothing seen" explained (issue 18): with no server in the domain, the
# viewer, the dashboard, the recorder and viscera-control each print, after
# 5 s without a match, the domain, the partition, the configuration file,
# whether DDS Security is on, and the likely causes; CYCLONEDDS_URI unset, so
# the configuration named is the default loopback file. Then a server starts
# and a second viewer, started with it, says nothing of the kind.
# usage: nothing_seen_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
unset CYCLONEDDS_URI
P=empty/seat01
"$BUILD/client/viewer/viscera-viewer" --partition $P --out "$OUT/frames" --duration 7 > "$OUT/viewer.log" 2>&1 &
PIDS+=("$!")
"$BUILD/client/dashboard/viscera-dashboard" --prefix empty --seats 1 --out "$OUT/dash" --duration 7 \
  > "$OUT/dashboard.log" 2>&1 & PIDS+=("$!")
# The recorder alone in its partition (viscera-control's writer would be a
# writer to record).
"$BUILD/client/recorder/viscera-recorder" --partition empty/rec --out "$OUT/rec.db" --duration 7 > "$OUT/recorder.log" 2>&1 &
PIDS+=("$!")
st=0
"$BUILD/client/control/viscera-control" --partition $P --wait 7 pause > "$OUT/control.log" 2>&1 || st=$?
[ $st = 1 ] || fail "viscera-control without a server exited $st, expected 1"
for p in "${PIDS[@]}"; do wait "$p" || fail "a client without a server failed (pid $p)"; done
PIDS=()
for w in viewer dashboard recorder control; do
  f="$OUT/$w.log"
  cat "$f"
  grep -q "nothing seen after 5 s" "$f" || fail "$w: no 'nothing seen' line"
  part=empty/seat01
  [ $w = recorder ] && part=empty/rec
  grep -q "listening on domain $VISCERA_DOMAIN, partition '$part" "$f" ||
    fail "$w: domain and partition not named"
  grep -q "configuration: file://.*cyclonedds-loopback.xml, DDS Security off" "$f" || fail "$w: configuration not named"
  grep -q "likely cause: no server runs on this domain and partition" "$f" || fail "$w: no likely cause"
  grep -q "refuse a participant without identity" "$f" || fail "$w: the secure-peers cause not named"
done
[ "$(grep -c 'nothing seen' "$OUT/control.log")" = 1 ] || fail "viscera-control explained more than once"

# With a server there: no explanation.
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $P --duration 9 --quiet \
  > "$OUT/server.log" 2>&1 & PIDS+=("$!")
"$BUILD/client/viewer/viscera-viewer" --partition $P --out "$OUT/frames2" --duration 7 > "$OUT/viewer2.log" 2>&1 ||
  fail "viewer with a server failed"
grep -q "viewer: scene" "$OUT/viewer2.log" || fail "the viewer did not see the server"
if grep -q "nothing seen" "$OUT/viewer2.log"; then fail "the viewer said 'nothing seen' with a server there"; fi
echo PASS
