#!/usr/bin/env bash
# Starts an N-seat classroom lab on this machine: one simulation server per
# seat (partition PREFIX/seatNN of one domain), optional scripted trainees,
# offscreen viewers per seat, and one recorder for the whole lab (PREFIX/*).
# With --secure, every process runs with its own DDS Security identity from
# a PKI made by deploy/pki.sh (generated into OUT/pki when missing).
# To spread a lab over machines, run it with --seats/--first on each machine
# and a LAN configuration (CYCLONEDDS_URI=file://deploy/cyclonedds-lan.xml).
#
# usage: deploy/lab.sh [options]
#   --build DIR         build directory (default: build/, built if missing)
#   --out DIR           logs, frames, recording (default: out/lab)
#   --seats N           seats on this machine (default 3)
#   --first K           number of the first seat (default 1)
#   --prefix P          partition prefix (default lab)
#   --scene FILE        scene every seat runs (default assets/scenes/default.yaml)
#   --trainees          a scripted haptic client per seat (palpate_kidney.traj)
#   --viewers K         offscreen viewers per seat (default 1)
#   --duration S        seconds the lab runs (default 20)
#   --secure            DDS Security on (PKI in OUT/pki)
#   --no-record         no lab recorder
# env: VISCERA_DOMAIN (default 9), CYCLONEDDS_URI (default the loopback config)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build" OUT="$ROOT/out/lab" SEATS=3 FIRST=1 PREFIX=lab SCENE="$ROOT/assets/scenes/default.yaml"
TRAINEES=0 VIEWERS=1 DURATION=20 SECURE=0 RECORD=1
usage() { sed -n 2,23p "$0" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --build) BUILD="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --seats) SEATS="$2"; shift 2 ;;
    --first) FIRST="$2"; shift 2 ;;
    --prefix) PREFIX="$2"; shift 2 ;;
    --scene) SCENE="$2"; shift 2 ;;
    --trainees) TRAINEES=1; shift ;;
    --viewers) VIEWERS="$2"; shift 2 ;;
    --duration) DURATION="$2"; shift 2 ;;
    --secure) SECURE=1; shift ;;
    --no-record) RECORD=0; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "lab.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
done
for v in SEATS FIRST VIEWERS DURATION; do
  [[ "${!v}" =~ ^[0-9]+$ ]] || { echo "lab.sh: --${v,,} must be a whole number" >&2; exit 2; }
done
[ "$SEATS" -ge 1 ] && [ $((FIRST + SEATS - 1)) -le 99 ] || { echo "lab.sh: seats must lie in 1..99" >&2; exit 2; }
[ -f "$SCENE" ] || { echo "lab.sh: scene file not found: $SCENE" >&2; exit 2; }
[ -x "$BUILD/server/viscera-server" ] || bash "$ROOT/deploy/build.sh" "$BUILD"
export VISCERA_DOMAIN="${VISCERA_DOMAIN:-9}"
NET="${CYCLONEDDS_URI:-file://$ROOT/deploy/cyclonedds-loopback.xml}"
mkdir -p "$OUT"
LAST=$((FIRST + SEATS - 1))
if [ $SECURE = 1 ] && [ ! -f "$OUT/pki/permissions.p7s" ]; then
  bash "$ROOT/deploy/pki.sh" "$OUT/pki" --seats "$LAST" --prefix "$PREFIX"
fi
as() { if [ $SECURE = 1 ]; then echo "$NET,file://$OUT/pki/identities/$1/security.xml"; else echo "$NET"; fi; }

pids=()
cleanup() { for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT INT TERM

echo "lab: seats $FIRST..$LAST on domain $VISCERA_DOMAIN, partitions $PREFIX/seatNN, $VIEWERS viewer(s) per seat," \
  "secure=$SECURE, $DURATION s; output in $OUT"
if [ $RECORD = 1 ]; then
  rm -f "$OUT/lab.db" "$OUT/lab.db-wal" "$OUT/lab.db-shm"
  CYCLONEDDS_URI="$(as recorder)" "$BUILD/client/recorder/viscera-recorder" --partition "$PREFIX/*" \
    --out "$OUT/lab.db" --scene "$PREFIX" --duration $((DURATION + 2)) --quiet > "$OUT/recorder.log" 2>&1 &
  pids+=($!)
fi
for i in $(seq "$FIRST" "$LAST"); do
  s=$(printf 'seat%02d' "$i")
  CYCLONEDDS_URI="$(as "server-$s")" "$BUILD/server/viscera-server" --scene "$SCENE" --partition "$PREFIX/$s" \
    --duration "$DURATION" > "$OUT/$s-server.log" 2>&1 &
  pids+=($!)
  for k in $(seq 1 "$VIEWERS"); do
    rm -rf "$OUT/$s-frames$k"
    CYCLONEDDS_URI="$(as observer)" "$BUILD/client/viewer/viscera-viewer" --partition "$PREFIX/$s" \
      --out "$OUT/$s-frames$k" --interval-ms 1000 --duration "$DURATION" > "$OUT/$s-viewer$k.log" 2>&1 &
    pids+=($!)
  done
done
if [ $TRAINEES = 1 ]; then
  sleep 2
  for i in $(seq "$FIRST" "$LAST"); do
    s=$(printf 'seat%02d' "$i")
    CYCLONEDDS_URI="$(as "trainee-$s")" "$BUILD/client/haptic/viscera-haptic" --partition "$PREFIX/$s" \
      --trajectory "$ROOT/assets/trajectories/palpate_kidney.traj" --quiet > "$OUT/$s-haptic.log" 2>&1 &
    pids+=($!)
  done
fi
wait || true
pids=()
echo "lab: done"
for i in $(seq "$FIRST" "$LAST"); do
  s=$(printf 'seat%02d' "$i")
  peak=$(sed -n 's/.*peak_force=\([0-9.]*\).*/\1/p' "$OUT/$s-haptic.log" 2>/dev/null || true)
  frames=$(cat "$OUT/$s"-frames*/frames.csv 2>/dev/null | grep -c png || true)
  step=$(grep -o 'step [^;]*median[^;,]*' "$OUT/$s-server.log" | tail -1 || true)
  echo "  $s: frames $frames${peak:+, trainee peak force $peak N}${step:+, $step}"
done
[ $RECORD = 1 ] && "$BUILD/client/recorder/viscera-recinfo" "$OUT/lab.db" | tail -1 | sed 's/^/  recording: /'
exit 0
