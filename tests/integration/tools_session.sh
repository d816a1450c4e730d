#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Shared by the tool tests (issue 4): one session with real processes over
# Cyclone DDS on loopback: server, recorder, offscreen viewer and one or
# more scripted haptic clients started together (one per "TOOL:TRAJ" pair).
# Source it, then: tools_session BUILD OUT SCENE TOOL:TRAJ [TOOL:TRAJ ...]
# Leaves server.out/.log, haptic<N>.csv/.log, frames/, session.db in OUT.
tools_session() {
  local build="$1" out="$2" scene="$3"; shift 3
  local domain="${VISCERA_DOMAIN:?}" part="test/$(basename "$out")"
  local common=(--domain "$domain" --partition "$part")
  mkdir -p "$out"; rm -rf "$out"/frames "$out"/session.db* "$out"/*.log "$out"/*.out "$out"/*.csv
  local pids=()
  "$build/server/viscera-server" --scene "$scene" "${common[@]}" >"$out/server.out" 2>"$out/server.log" &
  local server=$!; pids+=($server)
  "$build/client/recorder/viscera-recorder" "${common[@]}" --out "$out/session.db" --quiet \
    >"$out/recorder.out" 2>"$out/recorder.log" &
  local recorder=$!; pids+=($recorder)
  "$build/client/viewer/viscera-viewer" "${common[@]}" --out "$out/frames" --interval-ms 250 \
    >"$out/viewer.out" 2>"$out/viewer.log" &
  local viewer=$!; pids+=($viewer)
  trap 'kill -9 '"${pids[*]}"' 2>/dev/null || true' EXIT
  sleep 1.5 # discovery before the hands move
  local hp=() spec
  for spec in "$@"; do
    local tool="${spec%%:*}" traj="${spec#*:}"
    "$build/client/haptic/viscera-haptic" --trajectory "$traj" --tool "$tool" "${common[@]}" \
      --force-csv "$out/haptic$tool.csv" >"$out/haptic$tool.out" 2>"$out/haptic$tool.log" &
    hp+=($!)
  done
  local rc=0 p
  for p in "${hp[@]}"; do wait "$p" || rc=1; done
  sleep 0.5
  for p in $viewer $recorder $server; do kill -INT "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
  trap - EXIT
  return $rc
}
