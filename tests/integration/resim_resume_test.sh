#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Issue 16: a session resumed from a checkpoint re-simulates too.
#   1. a session cuts the tissue block (cut_block_mass_spring, the scalpel
#      script) with --checkpoint: at exit the file holds the cut topology,
#      the simulated time and the tool's measures;
#   2. the server restarts with that checkpoint (it resumes) and is recorded
#      while the scalpel works again;
#   3. `viscera-resim REC.db` alone starts from the recorded resume state
#      (RESUMED at the checkpoint's step, its sha256 the file's) and is bit
#      exact: every mesh frame of the restored and later topologies,
#      ObjectState, ToolMetrics (which carry the measures of run 1) and
#      events;
#   4. control: the same recording without its SceneSource (so without the
#      resume state), re-simulated from the scene file, starts from rest and
#      is not bit exact.
# Run 1 lasts beyond RESIM_SPAN_SLACK_S (10 s of simulated time): the resumed
# session's samples then carry sim times later than their wall-clock span
# since its SceneInfo, which viscera-resim once took for garbled ones and
# skipped, every one (a loaded machine's slow start made run 1 that long).
# usage: resim_resume_test.sh BUILD SRC OUT
set -uo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-207}"
rm -rf "$OUT"; mkdir -p "$OUT"
SCENE="$SRC/assets/scenes/cut_block_mass_spring.yaml"; TRAJ="$SRC/assets/trajectories/cut_block.traj"
SRV="$BUILD/server/viscera-server"; REC="$BUILD/client/recorder/viscera-recorder"
HAP="$BUILD/client/haptic/viscera-haptic"; RESIM="$BUILD/server/viscera-resim"
common=(--domain "$DOMAIN" --partition resim_resume)
CK="$OUT/session.ckpt"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do echo "--- $f"; tail -6 "$f"; done >&2; exit 1; }

# run N [record]: a session of the scene driven by the scalpel script.
run() {
  local n="$1" r="" t0=$SECONDS
  "$SRV" --scene "$SCENE" "${common[@]}" --checkpoint "$CK" >"$OUT/server$n.out" 2>"$OUT/server$n.log" &
  local s=$!; PIDS+=("$s")
  if [ "${2:-}" = record ]; then
    "$REC" "${common[@]}" --out "$OUT/session.db" >"$OUT/recorder.out" 2>"$OUT/recorder.log" & r=$!; PIDS+=("$r")
    for _ in $(seq 1 200); do grep -q "recording topic viscera_AppliedInput" "$OUT/recorder.log" && break; sleep 0.1; done
  else
    for _ in $(seq 1 200); do grep -q "running on domain" "$OUT/server$n.log" && break; sleep 0.1; done
  fi
  sleep 0.3
  "$HAP" --trajectory "$TRAJ" "${common[@]}" --quiet >"$OUT/haptic$n.out" 2>"$OUT/haptic$n.log" ||
    fail "run $n: the scalpel client failed"
  sleep 0.5
  if [ "$n" = 1 ]; then while [ $((SECONDS - t0)) -lt 12 ]; do sleep 0.2; done; fi
  kill -INT $s; wait $s || fail "run $n: the server failed"
  if [ -n "$r" ]; then sleep 0.3; kill -INT $r; wait $r || fail "the recorder failed"; fi
}

run 1
[ -s "$CK" ] || fail "run 1 wrote no checkpoint"
want_sha=$(sha256sum "$CK" | cut -d' ' -f1)
run 2 record
grep -q "resumed from checkpoint" "$OUT/server2.log" || fail "run 2 did not resume from the checkpoint"
step=$(sed -n 's/.*resumed from checkpoint .* (step \([0-9]*\)).*/\1/p' "$OUT/server2.log")
[ "${step:-0}" -gt 10500 ] || fail "run 1 ended at step ${step:-?}, not beyond 10.5 s of simulated time: the test cannot tell"
grep -q "topology" "$OUT/server1.log" "$OUT/server1.out" 2>/dev/null || true

"$RESIM" "$OUT/session.db" --quiet >"$OUT/resim.out" 2>"$OUT/resim.log"; rc=$?
cat "$OUT/resim.out"
grep -q "^RESUMED step=$step .*checkpoint_sha256=$want_sha " "$OUT/resim.out" ||
  fail "viscera-resim did not start from the recorded resume state (step $step, sha256 $want_sha)"
[ $rc -eq 0 ] && grep -q '^RESIM PASS .*bit_exact=1' "$OUT/resim.out" ||
  fail "the resumed session did not re-simulate bit for bit (exit $rc): $(cat "$OUT/resim.log")"
grep -q '^SCENE source=recording' "$OUT/resim.out" || fail "viscera-resim did not use the recording's own scene"

# Control: without its SceneSource the recording has no resume state; from rest it cannot reproduce run 2.
cp "$OUT/session.db" "$OUT/no_source.db"
sqlite3 "$OUT/no_source.db" "DELETE FROM samples WHERE topic_id = (SELECT id FROM topics WHERE name = 'viscera_SceneSource')" ||
  fail "sqlite3 failed"
"$RESIM" "$OUT/no_source.db" --scene "$SCENE" --quiet >"$OUT/control.out" 2>"$OUT/control.log"; crc=$?
grep -q '^RESUMED' "$OUT/control.out" && fail "control: a resume state was found without SceneSource"
[ $crc -ne 0 ] && ! grep -q 'bit_exact=1' "$OUT/control.out" ||
  fail "control: the resumed session re-simulated bit for bit from rest (exit $crc): the test cannot tell"
echo "control (from rest): exit $crc: $(grep '^RESIM' "$OUT/control.out" || head -c 300 "$OUT/control.log")"
echo "PASS: resumed at step $step, re-simulated bit for bit from the recording alone"
