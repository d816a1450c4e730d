#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Every instructor command reaches the lab's recording, under DDS Security.
# viscera-control ended as soon as the server answered; with security every
# reader is matched after its own key exchange, so the recorder's reader was
# often matched after the command had gone out (volatile) and a secure lab's
# recording held 3 of 5 instructor commands. One secure seat (PKI made here),
# the lab recorder (identity 'recorder', partition lab/*), six controls in a
# row (pause/resume), each its own viscera-control with the instructor's
# identity: the recording holds all six SessionControl commands (distinct
# seq), and the server applied six.
# usage: control_recorded_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
command -v openssl > /dev/null || fail "openssl missing (deploy/install_deps.sh installs it)"
bash "$SRC/deploy/pki.sh" "$OUT/pki" --seats 1 > "$OUT/pki.log" 2>&1 || fail "pki.sh failed"
as() { echo "file://$SRC/deploy/cyclonedds-loopback.xml,file://$OUT/pki/identities/$1/security.xml"; }
CYCLONEDDS_URI="$(as server-seat01)" "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" \
  --partition lab/seat01 > "$OUT/server.log" 2>&1 & SRV=$!; PIDS+=("$SRV")
CYCLONEDDS_URI="$(as recorder)" "$BUILD/client/recorder/viscera-recorder" --partition 'lab/*' --out "$OUT/lab.db" \
  > "$OUT/recorder.log" 2>&1 & REC=$!; PIDS+=("$REC")
# The recorder has the seat (its first topic from the server) before the commands.
for ((t = 0; t < 600; t++)); do grep -q "recording topic" "$OUT/recorder.log" 2>/dev/null && break; sleep 0.1; done
grep -q "recording topic" "$OUT/recorder.log" || fail "the recorder never saw the seat"
for verb in pause resume pause resume pause resume; do
  CYCLONEDDS_URI="$(as instructor)" "$BUILD/client/control/viscera-control" --partition lab/seat01 --wait 20 $verb \
    >> "$OUT/control.log" 2>&1 || fail "viscera-control $verb failed"
done
cat "$OUT/control.log"
applied=$(grep -c -E '^server: (paused|resumed)' "$OUT/server.log" || true)
[ "$applied" = 6 ] || fail "the server applied $applied of 6 commands"
kill -INT $REC; wait $REC || fail "the recorder failed"
kill -INT $SRV; wait $SRV || fail "server exited with an error"
PIDS=()
"$BUILD/client/recorder/viscera-recinfo" "$OUT/lab.db" --export jsonl --topic viscera_SessionControl "$OUT/controls.jsonl" \
  > /dev/null 2>&1 || fail "no SessionControl in the recording"
n=$(grep -o '"seq":[0-9]*' "$OUT/controls.jsonl" | sort -u | wc -l)
echo "SessionControl commands in the recording: $n of 6"
[ "$n" = 6 ] || fail "the recording holds $n of the 6 instructor commands"
echo PASS
