#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Tasks started by the instructor (issue 7 "starts tasks"), real processes on
# loopback: a kidney scene whose palpate_target task has `start: instructor`.
# A scripted probe (a haptic client) presses on the target and leaves.
# That first press must NOT start the task (with `start: first_command` it
# would start at the first command and complete at the first press). Then
# `viscera-control start-task find-spot` starts it (TASK_STARTED "by the
# instructor" with the station tag), and a second probe's press completes
# it. An unknown task name is refused with a reason. Asserted from the
# recording (SessionEvents in order, their simulated times, ToolMetrics) and
# the first probe's force log. Every step waits for the event before it (the
# first probe's exit, the control's answer, the server's "completed" line;
# 60 s at most, a safety stop), never for a wall-clock time (issue 15.6).
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
# The probe's trajectory starts when it has the server's scene (--wait-server).
cat > "$OUT/press_hold.traj" <<TRAJ
0.0   0.012  0.004  0.070
0.5   0.012  0.004  0.070
1.5   0.012  0.004  0.029
60.0  0.012  0.004  0.029
TRAJ
await() { for _ in $(seq 600); do grep -q -- "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done; return 1; }
CTL=("$BUILD/client/control/viscera-control" "${COMMON[@]}" --wait 60)
HAPTIC=("$BUILD/client/haptic/viscera-haptic" --tool 0 "${COMMON[@]}" --wait-server 60)
"$BUILD/server/viscera-server" --scene "$OUT/scene.yaml" "${COMMON[@]}" > "$OUT/server.out" 2> "$OUT/server.log" &
SRV=$!; PIDS+=($SRV)
"$BUILD/client/recorder/viscera-recorder" "${COMMON[@]}" --out "$OUT/session.db" --quiet \
  > "$OUT/recorder.out" 2> "$OUT/recorder.log" & REC=$!; PIDS+=($REC)
# 1. The first probe presses until it has felt the tissue for 200 of its
# ticks (its force log's in_contact), then leaves (SIGINT).
"${HAPTIC[@]}" --trajectory "$OUT/press_hold.traj" --force-csv "$OUT/probe.csv" \
  > "$OUT/haptic.out" 2> "$OUT/haptic.log" & HAP=$!; PIDS+=($HAP)
touched() { awk -F, 'NR > 1 && $8 == 1 { n++ } END { print n + 0 }' "$OUT/probe.csv" 2>/dev/null || echo 0; }
for _ in $(seq 600); do [ "$(touched)" -ge 200 ] && break; sleep 0.1; done
kill -INT $HAP; wait $HAP || fail "the first probe failed"
# 2. The instructor: an unknown task refused, then find-spot started.
if "${CTL[@]}" start-task no-such-task > "$OUT/ctl.log" 2>&1; then fail "an unknown task was started"; fi
grep -q "refused: .*no task of that name" "$OUT/ctl.log" || fail "unknown task not refused with its reason"
"${CTL[@]}" --station 7 start-task find-spot >> "$OUT/ctl.log" 2>&1 || fail "start-task not applied"
cat "$OUT/ctl.log"
# 3. The second probe presses until the server completes the task.
"${HAPTIC[@]}" --trajectory "$OUT/press_hold.traj" > "$OUT/haptic2.out" 2> "$OUT/haptic2.log" & HAP=$!; PIDS+=($HAP)
await "$OUT/server.log" "task 'find-spot' completed" || fail "the second press did not complete the task"
kill -INT $HAP; wait $HAP || fail "the second probe failed"
# The server publishes its final ToolMetrics as it exits (a reliable writer
# lingers for the recorder's acknowledgement): stop it before the recorder.
for p in $SRV $REC; do kill -INT "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
PIDS=()

# The first press touched the tissue (ticks in contact in the first probe's
# log; it had exited before the instructor's start).
first=$(awk -F, 'NR > 1 && $8 == 1 { n++ } END { print n + 0 }' "$OUT/probe.csv")
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
# The operation time is counted from the instructor's start: it equals the
# simulated time between TASK_STARTED and TASK_COMPLETED (the server's own
# clock), and ToolMetrics agrees.
st=$(grep '^EVENT TASK_STARTED ' "$OUT/rec.txt")
awk -v t="$(val "$e" value)" -v s0="$(val "$st" sim)" -v s1="$(val "$e" sim)" -v c="$(val "$m" tasks_completed)" \
  -v op="$(val "$m" operation_time)" \
  'BEGIN { d = op - t; g = (s1 - s0) - t; printf "operation time %.3f s, simulated %.3f -> %.3f s\n", t, s0, s1
           exit !(t > 0 && s1 > s0 && g < 0.002 && g > -0.002 && c == 1 && d < 0.002 && d > -0.002) }' \
  || fail "operation time or metrics wrong: $st / $e / $m"
grep -q '^TASK task=find-spot kind=palpate_target tool=probe state=completed ' "$OUT/server.out" || fail "server TASK line"
echo PASS
