#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Feedback before the tissue step (issue 17 item 5), end to end: a real
# server on the default scene, the recorder and a scripted haptic client
# (palpate_kidney.traj: press, hold, release), each a process over DDS on
# loopback. Judged from the recording alone (rec_feedback_first): the first
# ContactFeedback answering each command the server took carries the
# simulated time at the start of the step that took it (written before
# the tissue step, not after it), never two samples of a tool in one step,
# and the haptic client measured its round trips. No wall-clock check.
# usage: feedback_first_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-228}"
PART=feedback_first/test
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  for f in "$OUT"/*.log "$OUT"/*.out; do [ -s "$f" ] && { echo "--- $f"; tail -8 "$f"; }; done >&2
  exit 1
}
rm -rf "$OUT"; mkdir -p "$OUT"
common=(--domain "$DOMAIN" --partition "$PART")

"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" "${common[@]}" \
  >"$OUT/server.out" 2>"$OUT/server.log" &
SERVER=$!; pids+=($SERVER)
"$BUILD/client/recorder/viscera-recorder" "${common[@]}" --out "$OUT/session.db" --quiet \
  >"$OUT/recorder.out" 2>"$OUT/recorder.log" &
RECORDER=$!; pids+=($RECORDER)
sleep 1.5
"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/palpate_kidney.traj" "${common[@]}" \
  >"$OUT/haptic.out" 2>"$OUT/haptic.log" || fail "haptic client failed"
sleep 0.5
kill -INT $SERVER; wait $SERVER || true
sleep 0.5
kill -INT $RECORDER; wait $RECORDER || true
pids=()

sum=$(grep '^SUMMARY ' "$OUT/haptic.out") || fail "no SUMMARY line from the haptic client"
n=$(echo "$sum" | tr ' ' '\n' | sed -n 's/^latency_samples=//p')
[ "${n:-0}" -ge 1000 ] || fail "the haptic client measured only ${n:-0} round trips"
# A 5 s palpation at 1 kHz: well over 1000 commands taken even under load; a few feedback
# samples may be missing from the recording (best effort), most are there.
"$BUILD/tests/integration/rec_feedback_first" "$OUT/session.db" 1000 >"$OUT/check.out" 2>"$OUT/check.log" ||
  fail "$(cat "$OUT/check.out")"
cat "$OUT/check.out"
echo "PASS"
