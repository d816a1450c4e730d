#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Runs one complete local session on loopback: server, recorder, offscreen
# viewer and a scripted haptic client, each a separate process talking over
# Cyclone DDS. Used by demo.sh and by the integration tests.
#
# usage: deploy/session.sh BUILD_DIR OUT_DIR [SCENE] [TRAJECTORY]
# env:   VISCERA_DOMAIN (default 0, like every binary), VISCERA_PARTITION (default demo/seat01),
#        VIEWER_ARGS, SERVER_ARGS (extra options), CYCLONEDDS_URI (default the
#        loopback configuration; another one needs a security fragment in it, or
#        VISCERA_INSECURE=1, which warns: deploy/net_guard.sh)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$1"
OUT="$2"
SCENE="${3:-$ROOT/assets/scenes/default.yaml}"
TRAJ="${4:-$ROOT/assets/trajectories/palpate_kidney.traj}"
DOMAIN="${VISCERA_DOMAIN:-0}"
PART="${VISCERA_PARTITION:-demo/seat01}"
export CYCLONEDDS_URI="${CYCLONEDDS_URI:-file://$ROOT/deploy/cyclonedds-loopback.xml}"
# shellcheck source=net_guard.sh
source "$ROOT/deploy/net_guard.sh"
net_guard session.sh "$CYCLONEDDS_URI" 0 "${VISCERA_INSECURE:-0}" \
  "add an identity fragment from deploy/pki.sh to it, or set VISCERA_INSECURE=1 to run without DDS Security" || exit 2

mkdir -p "$OUT"
rm -rf "$OUT/frames" "$OUT/session.db" "$OUT/session.db-wal" "$OUT/session.db-shm"
common=(--domain "$DOMAIN" --partition "$PART")
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
trap cleanup EXIT

echo "session: domain $DOMAIN, partition '$PART', output in $OUT"
"$BUILD/server/viscera-server" --scene "$SCENE" "${common[@]}" ${SERVER_ARGS:-} >"$OUT/server.out" 2>"$OUT/server.log" &
SERVER=$!; pids+=("$SERVER")
# The recording names its scene (viscera-recinfo's "scene:"): the file's own
# `scene:` name, or the file's stem if that line is not found.
SCENE_NAME=$(sed -n 's/^scene:[[:space:]]*\([A-Za-z0-9_-]*\).*/\1/p' "$SCENE" 2>/dev/null | head -n 1)
[ -n "$SCENE_NAME" ] || SCENE_NAME=$(basename "$SCENE" .yaml)
"$BUILD/client/recorder/viscera-recorder" "${common[@]}" --out "$OUT/session.db" --scene "$SCENE_NAME" --quiet \
  >"$OUT/recorder.out" 2>"$OUT/recorder.log" &
RECORDER=$!; pids+=("$RECORDER")
"$BUILD/client/viewer/viscera-viewer" "${common[@]}" --out "$OUT/frames" ${VIEWER_ARGS:---interval-ms 100} \
  >"$OUT/viewer.out" 2>"$OUT/viewer.log" &
VIEWER=$!; pids+=("$VIEWER")
# A process that stopped early has said why in its log: a server that refused
# its scene (a wrong field, a missing mesh), a viewer or recorder that refused
# its options. The user sees that, not a hand waiting for a server that is
# gone or a session without frames. gone NAME PID: prints NAME's log tail and
# succeeds when that process has exited.
gone() {
  kill -0 "$2" 2>/dev/null && return 1
  echo "session: the $1 exited (see $OUT/$1.log):" >&2
  tail -n 5 "$OUT/$1.log" | sed 's/^/  /' >&2
  return 0
}
# Let the viewer and recorder discover the server before the hand moves.
sleep 1.5
if gone server "$SERVER" || gone viewer "$VIEWER" || gone recorder "$RECORDER"; then exit 1; fi
# set -e would end the script here, silently, on a failing client.
HAPTIC_RC=0
"$BUILD/client/haptic/viscera-haptic" --trajectory "$TRAJ" "${common[@]}" \
  --force-csv "$OUT/haptic_force.csv" --rt-priority 50 >"$OUT/haptic.out" 2>"$OUT/haptic.log" || HAPTIC_RC=$?
if [ $HAPTIC_RC -ne 0 ] && gone server "$SERVER"; then exit 1; fi
sleep 0.5
# Each stops cleanly (status 0) on SIGINT; any other status is its own failure.
FAILED=()
for entry in "viewer:$VIEWER" "recorder:$RECORDER" "server:$SERVER"; do
  name=${entry%%:*} pid=${entry#*:} rc=0
  kill -INT "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || rc=$?
  [ $rc -eq 0 ] || FAILED+=("$name (status $rc)")
done
pids=()
trap - EXIT
for f in "${FAILED[@]}"; do
  name=${f%% *}
  echo "session: the $f failed (see $OUT/$name.log):" >&2
  tail -n 5 "$OUT/$name.log" | sed 's/^/  /' >&2
done
if [ $HAPTIC_RC -ne 0 ]; then
  echo "session: haptic client failed, status $HAPTIC_RC (see $OUT/haptic.log):" >&2
  tail -n 5 "$OUT/haptic.log" | sed 's/^/  /' >&2
  exit 1
fi
[ ${#FAILED[@]} -eq 0 ] || exit 1
