#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Every shipped scene re-simulates from its recording alone (issue 16 item 6):
# for each scene in assets/scenes, a real server, the recorder and one
# scripted haptic client per driven tool (the scene's trajectory: palpation
# for the probes, the grasp, cut or stone-removal script for the other
# tools), each a process over DDS on loopback; then `viscera-resim REC.db`
# with no scene file (the recording's SceneSource) must exit 0 with
# bit_exact=1: every mesh frame of every topology version, every
# ObjectState and every interaction event reproduced bit for bit from the
# recorded AppliedInput (buttons, orientation, releases).
# Suite time (issue 16): the scripts are played at twice their speed (times
# halved: every button, orientation and waypoint is still sent, in less
# simulated time to record and re-simulate), five sessions record at a
# time on partitions of their own and two re-simulations run at a time.
# That the shortened scripts still exercise what each scene is for is
# checked from the server's own log: the cuts change the topology, the
# grasper and the extractor grasp, stone_removal's tasks complete, and every
# probe touches the tissue.
# usage: resim_scenes_test.sh BUILD SRC OUT
set -uo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-197}"
rm -rf "$OUT"; mkdir -p "$OUT/traj"
# The shipped scripts with their times scaled by VISCERA_RESIM_SPEED_SCALE (0.5: twice as fast).
SCALE="${VISCERA_RESIM_SPEED_SCALE:-0.5}"
for f in "$SRC"/assets/trajectories/*.traj; do
  awk -v k="$SCALE" '/^[ \t]*(#|$)/ { print; next } { $1 = sprintf("%.4f", $1 * k); print }' "$f" \
    >"$OUT/traj/$(basename "$f")"
done
T="$OUT/traj"

# scene -> TOOL:TRAJECTORY ... (the probes palpate; every other tool kind its own script)
drives() {
  case "$1" in
    grasp_pull) echo "0:$T/grasp_pull_kidney.traj" ;;
    cut_block_mass_spring) echo "0:$T/cut_block.traj" ;;
    cut_spleen_xpbd) echo "0:$T/cut_spleen.traj" ;;
    stone_removal) echo "0:$T/palpate_kidney.traj 1:$T/stone_removal_extractor.traj" ;;
    two_tools | bench_two_tools) echo "0:$T/palpate_kidney.traj 1:$T/two_tools_probe2.traj" ;;
    *) echo "0:$T/palpate_kidney.traj" ;;
  esac
}

# record NAME SCENE: one session into $OUT/NAME/session.db.
record() {
  local name="$1" scene="$2" d="$OUT/$1"
  local common=(--domain "$DOMAIN" --partition "resim_scenes/$name")
  mkdir -p "$d"
  "$BUILD/server/viscera-server" --scene "$scene" "${common[@]}" >"$d/server.out" 2>"$d/server.log" &
  local s=$!
  "$BUILD/client/recorder/viscera-recorder" "${common[@]}" --out "$d/session.db" \
    >"$d/recorder.out" 2>"$d/recorder.log" &
  local r=$!
  # The hands move once the recorder records the server's inputs (at most 20 s).
  for _ in $(seq 1 200); do grep -q "recording topic viscera_AppliedInput" "$d/recorder.log" && break; sleep 0.1; done
  sleep 0.3
  local hp=() spec rc=0
  for spec in $(drives "$name"); do
    "$BUILD/client/haptic/viscera-haptic" --trajectory "${spec#*:}" --tool "${spec%%:*}" "${common[@]}" --quiet \
      >"$d/haptic${spec%%:*}.out" 2>"$d/haptic${spec%%:*}.log" &
    hp+=($!)
  done
  for p in "${hp[@]}"; do wait "$p" || rc=1; done
  sleep 0.5
  kill -INT $s; wait $s || rc=1
  sleep 0.3
  kill -INT $r; wait $r || rc=1
  echo $rc >"$d/record.rc"
}

scenes=("$SRC"/assets/scenes/*.yaml)
# VISCERA_RESIM_SCENES="a b": only those (the sanitizer pass keeps the ones
# with buttons, cuts, grasps and two tools: its physics runs 2-3 times slower).
if [ -n "${VISCERA_RESIM_SCENES:-}" ]; then
  scenes=()
  for n in $VISCERA_RESIM_SCENES; do scenes+=("$SRC/assets/scenes/$n.yaml"); done
fi
BATCH="${VISCERA_RESIM_BATCH:-5}"
for ((i = 0; i < ${#scenes[@]}; i += BATCH)); do
  pids=()
  for sc in "${scenes[@]:i:BATCH}"; do
    record "$(basename "$sc" .yaml)" "$sc" & pids+=($!)
  done
  trap 'kill -9 '"${pids[*]}"' 2>/dev/null || true' EXIT
  wait "${pids[@]}"
done
trap - EXIT

resim() {
  "$BUILD/server/viscera-resim" "$OUT/$1/session.db" --quiet >"$OUT/$1/resim.out" 2>"$OUT/$1/resim.log"
  echo $? >"$OUT/$1/resim.rc"
}
for ((i = 0; i < ${#scenes[@]}; i += 2)); do
  pids=()
  for sc in "${scenes[@]:i:2}"; do
    name=$(basename "$sc" .yaml)
    [ "$(cat "$OUT/$name/record.rc" 2>/dev/null)" = 0 ] && { resim "$name" & pids+=($!); }
  done
  [ ${#pids[@]} -gt 0 ] && wait "${pids[@]}"
done

# exercised NAME: what the scene is for happened in the recorded session
# (the server's log and summary); prints what is missing.
exercised() {
  local d="$OUT/$1" miss=""
  case "$1" in
    cut_block_mass_spring | cut_spleen_xpbd)
      grep -q "ends its cut of organ .*: [1-9][0-9]* topology change" "$d/server.log" || miss="no topology change" ;;
    grasp_pull) grep -q "grasps organ 'kidney'" "$d/server.log" || miss="no grasp" ;;
    stone_removal)
      grep -q "grasps stone" "$d/server.log" || miss="no stone grasp"
      grep -q "task 'remove-stone' completed" "$d/server.log" || miss="$miss remove-stone not completed" ;;
  esac
  local line
  while read -r line; do
    awk -v l="$line" 'BEGIN { split(l, f, " "); for (i in f) if (f[i] ~ /^contact_time=/) { sub(/^contact_time=/, "", f[i]); exit !(f[i] > 0) } exit 1 }' ||
      miss="$miss probe without contact ($line)"
  done < <(grep '^PALPATION tool=probe' "$d/server.out" | cut -d' ' -f1-3)
  echo "$miss"
}

failures=0
for sc in "${scenes[@]}"; do
  name=$(basename "$sc" .yaml); d="$OUT/$name"
  if [ "$(cat "$d/record.rc" 2>/dev/null)" != 0 ]; then
    echo "FAIL $name: the session did not run"; tail -3 "$d"/*.log; failures=$((failures + 1)); continue
  fi
  rc=$(cat "$d/resim.rc")
  line=$(grep '^RESIM ' "$d/resim.out")
  inputs=$(grep '^INPUTS ' "$d/resim.out")
  miss=$(exercised "$name")
  if [ -n "${miss// /}" ]; then
    echo "FAIL $name: the session did not exercise the scene: $miss"; failures=$((failures + 1))
    # what the server and the hands saw (a stall of the server longer than a
    # script's hold, or a hand that started late, shows here)
    grep -E "grasp|stone|task|overrun|behind|steps, step time|simulated s per wall" "$d/server.log" | tail -8
    for f in "$d"/haptic*.log; do echo "--- $f"; tail -3 "$f"; done
    continue
  fi
  if [ $rc -eq 0 ] && echo "$line" | grep -q 'bit_exact=1' && echo "$inputs" | grep -q 'mode=applied' &&
    grep -q '^SCENE source=recording' "$d/resim.out"; then
    echo "ok   $name: $(grep -c '^ORGAN' "$d/resim.out") organ(s), $inputs; $line"
  else
    echo "FAIL $name: viscera-resim exit $rc: $line"; cat "$d/resim.out" "$d/resim.log"
    failures=$((failures + 1))
  fi
done
[ $failures -eq 0 ] && echo PASS || { echo "$failures scene(s) did not re-simulate bit for bit"; exit 1; }
