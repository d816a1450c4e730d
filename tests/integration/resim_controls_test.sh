#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Re-simulation of every input the server applied (issue 16 item 1): a
# stone_removal session with two tools (probe palpating, extractor taking the
# stone), a second station guiding the probe (its commands mixed in by the
# server) and an instructor's SessionControls while the hands move: guide,
# thresholds, pause, resume, start-task, material (a rebuild), reset (a
# rebuild), release, assign. Real processes over DDS on loopback. Then:
#   1. `viscera-resim REC.db` (the recording alone) exits 0 with every frame,
#      object and interaction event bit for bit, having replayed every
#      control and both rebuilds (INPUTS line);
#   2. negative control: with the AppliedInput samples of the controls
#      deleted from a copy, the same recording must fail (exit 1): the
#      controls matter and resim notices their absence.
# usage: resim_controls_test.sh BUILD SRC OUT
set -uo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-198}"
T="$SRC/assets/trajectories"
fail() {
  echo "FAIL: $*" >&2
  for f in "$OUT"/*.log "$OUT"/*.out; do [ -s "$f" ] && { echo "--- $f"; tail -6 "$f"; }; done >&2
  exit 1
}
rm -rf "$OUT"; mkdir -p "$OUT"
common=(--domain "$DOMAIN" --partition resim/controls)
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done' EXIT
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/stone_removal.yaml" "${common[@]}" \
  >"$OUT/server.out" 2>"$OUT/server.log" & S=$!; pids+=($S)
"$BUILD/client/recorder/viscera-recorder" "${common[@]}" --out "$OUT/session.db" \
  >"$OUT/recorder.out" 2>"$OUT/recorder.log" & R=$!; pids+=($R)
# The hands move once the recorder records the server's inputs (at most 20 s).
for _ in $(seq 1 200); do grep -q "recording topic viscera_AppliedInput" "$OUT/recorder.log" && break; sleep 0.1; done
sleep 0.3
hp=()
"$BUILD/client/haptic/viscera-haptic" --trajectory "$T/palpate_kidney.traj" --tool 0 --station alice "${common[@]}" \
  --quiet >"$OUT/haptic_alice.out" 2>"$OUT/haptic_alice.log" & hp+=($!)
"$BUILD/client/haptic/viscera-haptic" --trajectory "$T/palpate_kidney_expert.traj" --tool 0 --station bob \
  "${common[@]}" --quiet >"$OUT/haptic_bob.out" 2>"$OUT/haptic_bob.log" & hp+=($!)
"$BUILD/client/haptic/viscera-haptic" --trajectory "$T/stone_removal_extractor.traj" --tool 1 "${common[@]}" \
  --quiet >"$OUT/haptic_ext.out" 2>"$OUT/haptic_ext.log" & hp+=($!)
pids+=("${hp[@]}")
ctl() { "$BUILD/client/control/viscera-control" "${common[@]}" --wait 10 "$@" >>"$OUT/control.out" 2>&1; }
sleep 0.3
ctl guide 0 bob 0.5 || fail "guide refused"
ctl thresholds 0 0.5 1 2 || fail "thresholds refused"
ctl pause || fail "pause refused"
sleep 0.2
ctl resume || fail "resume refused"
ctl start-task find-spot || fail "start-task refused"
ctl material 0 45 -1 -1 -1 || fail "material refused"
sleep 0.3
ctl reset || fail "reset refused"
ctl release 0 || fail "release refused"
ctl assign 0 alice || fail "assign refused"
for p in "${hp[@]}"; do wait "$p" || fail "a haptic client failed"; done
sleep 0.5
kill -INT $S; wait $S || fail "server exited with an error"
sleep 0.3
kill -INT $R; wait $R
pids=()

echo "== 1. re-simulate from the recording alone"
"$BUILD/server/viscera-resim" "$OUT/session.db" --quiet >"$OUT/resim.out" 2>"$OUT/resim.log"
rc=$?
grep -v '^SCHEDULE' "$OUT/resim.out"
[ $rc -eq 0 ] || fail "viscera-resim exit $rc"
grep -q '^RESIM PASS .*bit_exact=1' "$OUT/resim.out" || fail "not bit for bit"
inputs=$(grep '^INPUTS mode=applied' "$OUT/resim.out") || fail "no applied inputs"
ctls=$(echo "$inputs" | sed -n 's/.* controls=\([0-9]*\).*/\1/p')
rebuilds=$(echo "$inputs" | sed -n 's/.* rebuilds=\([0-9]*\).*/\1/p')
[ "${ctls:-0}" -ge 9 ] || fail "only ${ctls:-0} controls replayed, 9 sent"
[ "${rebuilds:-0}" -eq 2 ] || fail "${rebuilds:-0} rebuilds replayed, expected 2 (material, reset)"
grep -q '^ORGAN kidney .* keyframes=[3-9]' "$OUT/resim.out" || fail "the rebuilds' keyframes were not compared"

echo "== 2. without the controls' AppliedInput the recording does not re-simulate"
cp "$OUT/session.db" "$OUT/nocontrols.db"
# rec_applied names the AppliedInput samples that carry a control (ROWS on stderr).
"$BUILD/tests/integration/rec_applied" "$OUT/session.db" >"$OUT/applied.out" 2>"$OUT/applied.log" ||
  fail "rec_applied failed: $(cat "$OUT/applied.log")"
rows=$(sed -n 's/^ROWS //p' "$OUT/applied.log")
[ -n "$rows" ] || fail "no AppliedInput sample with a control recorded"
sqlite3 "$OUT/nocontrols.db" "DELETE FROM samples WHERE id IN ($rows)" || fail "cannot edit the copy"
"$BUILD/server/viscera-resim" "$OUT/nocontrols.db" --quiet >"$OUT/resim_nc.out" 2>"$OUT/resim_nc.log"
rc=$?
tail -3 "$OUT/resim_nc.log"
[ $rc -eq 1 ] || fail "without the controls viscera-resim exited $rc, expected 1"
echo PASS
