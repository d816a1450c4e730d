#!/usr/bin/env bash
# Tasks started by the instructor (issue 7 "starts tasks"), real processes on
# loopback: a kidney scene whose palpate_target task has `start: instructor`.
# A scripted probe presses on the target (wall 1.5-3 s of its trajectory),
# lifts, and presses again from 9 s. The first press must NOT start the task
# (with `start: first_command` it would start at the first command and
# complete at the first press); `viscera-control start-task find-spot`,
# sent at about 5 s while the probe is lifted, starts it (TASK_STARTED "by
# the instructor" with the station tag), and the second press completes it.
# An unknown task name is refused with a reason. Asserted from the recording
# (SessionEvents in order, ToolMetrics) and the probe's force log.
# usage: start_task_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
PART=test/start_task
COMMON=(--domain "${VISCERA_DOMAIN:?}" --partition $PART)
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do echo "--- $f"; tail -6 "$f"; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
cat > "$OUT/scene.yaml" <<YAML
scene: start-task
physics: {dt: 0.001, publish_hz: 30}
organs:
  - {name: kidney, mesh: $SRC/assets/meshes/kidney.obj, model: mass_spring_surface,
     material: {mass: 0.15, stiffness: 30, damping: 0.02, home_stiffness: 30, home_damping: 0.005}}
tools:
  - {name: probe, kind: probe, radius: 0.003, stiffness: 400, max_force: 4}
tasks:
  - {name: find-spot, kind: palpate_target, tool: probe, target: [0.012, 0.004, 0.034], target_radius: 0.006,
     start: instructor}
YAML
cat > "$OUT/probe.traj" <<TRAJ
0.0   0.012  0.004  0.070
0.5   0.012  0.004  0.070
1.5   0.012  0.004  0.029
3.0   0.012  0.004  0.029
3.8   0.012  0.004  0.070
8.0   0.012  0.004  0.070
9.0   0.012  0.004  0.029
13.0  0.012  0.004  0.029
13.5  0.012  0.004  0.070
TRAJ
CTL=("$BUILD/client/control/viscera-control" "${COMMON[@]}" --wait 8)
"$BUILD/server/viscera-server" --scene "$OUT/scene.yaml" "${COMMON[@]}" > "$OUT/server.out" 2> "$OUT/server.log" &
SRV=$!; PIDS+=($SRV)
"$BUILD/client/recorder/viscera-recorder" "${COMMON[@]}" --out "$OUT/session.db" --quiet \
  > "$OUT/recorder.out" 2> "$OUT/recorder.log" & REC=$!; PIDS+=($REC)
sleep 1.5 # discovery before the hand moves
"$BUILD/client/haptic/viscera-haptic" --trajectory "$OUT/probe.traj" --tool 0 "${COMMON[@]}" \
  --force-csv "$OUT/probe.csv" > "$OUT/haptic.out" 2> "$OUT/haptic.log" & HAP=$!; PIDS+=($HAP)
sleep 5 # the first press is over (trajectory 1.5-3.8 s), the probe is lifted
if "${CTL[@]}" start-task no-such-task > "$OUT/ctl.log" 2>&1; then fail "an unknown task was started"; fi
grep -q "refused: .*no task of that name" "$OUT/ctl.log" || fail "unknown task not refused with its reason"
"${CTL[@]}" --station 7 start-task find-spot >> "$OUT/ctl.log" 2>&1 || fail "start-task not applied"
cat "$OUT/ctl.log"
wait $HAP || fail "haptic client failed"
sleep 0.5
for p in $REC $SRV; do kill -INT "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
PIDS=()

# The first press touched the tissue (in_contact in the probe's log before 4 s).
first=$(awk -F, 'NR > 1 && $1 < 4.0 && $8 == 1 { n++ } END { print n + 0 }' "$OUT/probe.csv")
[ "$first" -gt 100 ] || fail "the probe did not touch during its first press ($first contact ticks)"
"$BUILD/tests/integration/rec_tools" "$OUT/session.db" > "$OUT/rec.txt" || fail "rec_tools failed"
grep -E '^EVENT TASK_|^TOOLMETRICS' "$OUT/rec.txt"
# Exactly one start, the instructor's (station 7), then exactly one completion.
[ "$(grep -c '^EVENT TASK_STARTED ' "$OUT/rec.txt")" -eq 1 ] || fail "expected one TASK_STARTED (the tool's first move must not start it)"
grep -q "^EVENT TASK_STARTED tool=0 .*task 'find-spot' started by the instructor .*\[station 7 seq" "$OUT/rec.txt" \
  || fail "TASK_STARTED does not say the instructor started it"
[ "$(grep -c '^EVENT TASK_COMPLETED ' "$OUT/rec.txt")" -eq 1 ] || fail "expected one TASK_COMPLETED"
order=$(grep -n -E '^EVENT TASK_(STARTED|COMPLETED) ' "$OUT/rec.txt" | cut -d' ' -f2 | tr '\n' ' ')
[ "$order" = "TASK_STARTED TASK_COMPLETED " ] || fail "completion before the instructor's start: $order"
val() { echo "$1" | tr ' ' '\n' | sed -n "s/^$2=//p"; }
e=$(grep '^EVENT TASK_COMPLETED ' "$OUT/rec.txt")
m=$(grep '^TOOLMETRICS tool=0 ' "$OUT/rec.txt") || fail "no ToolMetrics for the probe"
# Operation time from the instructor's start (about 4 s of lifted wait plus
# the descent; less when a loaded server lags), agreeing with ToolMetrics.
awk -v t="$(val "$e" value)" -v c="$(val "$m" tasks_completed)" -v op="$(val "$m" operation_time)" \
  'BEGIN { d = op - t; exit !(t > 0.5 && t < 12 && c == 1 && d < 0.002 && d > -0.002) }' \
  || fail "operation time or metrics wrong: $e / $m"
grep -q '^TASK task=find-spot kind=palpate_target tool=probe state=completed ' "$OUT/server.out" || fail "server TASK line"
echo PASS
