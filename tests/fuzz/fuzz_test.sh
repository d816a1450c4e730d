#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Garbage in, seat keeps serving (issue 7, fault tolerance). A server and a
# viewer run; fuzz_dds sends thousands of mutated ToolCommand, SessionControl,
# MeshState and MeshDelta samples (corpus in tests/fuzz/corpus, fixed seed)
# into the seat's partition; then a scripted haptic client palpates.
# Asserts: server and viewer are still running after the fuzz; the server
# reported rejected input; the palpation afterwards gets contact force; the
# server ends normally (exit 0) and the viewer keeps writing frames.
# usage: fuzz_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do echo "--- $f"; tail -8 "$f"; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT/frames"
PART=viscera/fuzz

"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $PART --duration 22 \
  > "$OUT/server.log" 2>&1 & SRV=$!; PIDS+=($SRV)
"$BUILD/client/viewer/viscera-viewer" --partition $PART --out "$OUT/frames" --interval-ms 500 --duration 21 \
  > "$OUT/viewer.log" 2>&1 & VIEW=$!; PIDS+=($VIEW)
sleep 1.5
"$BUILD/tests/fuzz/fuzz_dds" --corpus "$SRC/tests/fuzz/corpus" --partition $PART --samples 20000 --seconds 8 \
  --seed 12345 > "$OUT/fuzz.log" 2>&1 || fail "fuzz_dds failed"
cat "$OUT/fuzz.log"
delivered=$(sed -n 's/^fuzz_dds: \([0-9]*\) mutated samples delivered.*/\1/p' "$OUT/fuzz.log")
[ "${delivered:-0}" -gt 1000 ] || fail "too few mutated samples got past DDS (${delivered:-0}): the fuzz tested nothing"
kill -0 $SRV 2>/dev/null || fail "the server died under fuzzing"
kill -0 $VIEW 2>/dev/null || fail "the viewer died under fuzzing"
grep -q "rejected" "$OUT/server.log" || fail "the server reported no rejected input"
# Well-formed mutated SessionControl samples may have paused the seat or set
# other thresholds: without DDS Security anyone may (the security test shows
# that with it only instructors can). An instructor resumes and restores.
"$BUILD/client/control/viscera-control" --partition $PART --station 4242 resume > "$OUT/resume.log" 2>&1 \
  || fail "the server did not answer a resume after the fuzz"
"$BUILD/client/control/viscera-control" --partition $PART --station 4242 thresholds 0 0.5 0.8 1.5 \
  >> "$OUT/resume.log" 2>&1 || fail "the server did not answer a thresholds command after the fuzz"

"$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/palpate_kidney.traj" --partition $PART \
  --quiet > "$OUT/haptic.log" 2>&1 || fail "haptic client failed after the fuzz"
peak=$(sed -n 's/.*peak_force=\([0-9.]*\).*/\1/p' "$OUT/haptic.log")
echo "palpation after the fuzz: peak force ${peak:-none} N"
awk -v f="${peak:-0}" 'BEGIN { exit !(f > 0.3) }' || fail "no contact force after the fuzz"
wait $SRV || fail "server exited with an error"
wait $VIEW || true
PIDS=()
frames=$(ls "$OUT/frames"/*.png 2>/dev/null | wc -l)
echo "viewer frames: $frames"
[ "$frames" -ge 20 ] || fail "viewer stopped writing frames ($frames)"
echo PASS
