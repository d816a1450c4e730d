#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Starts an N-seat classroom lab on this machine: one simulation server per
# seat (partition PREFIX/seatNN of one domain), optional scripted trainees,
# offscreen viewers per seat, and one recorder for the whole lab (PREFIX/*).
# With --secure, every process runs with its own DDS Security identity from
# a PKI made by deploy/pki.sh (generated into --pki DIR when missing).
# To spread a lab over machines, run it with --seats/--first on each machine
# and a LAN configuration (CYCLONEDDS_URI=file://deploy/cyclonedds-lan.xml);
# one machine records (the others --no-record) and, with --secure, all use
# copies of one PKI (--pki).
#
# usage: deploy/lab.sh [options]
#   --build DIR         build directory (default: build/, built if missing)
#   --out DIR           logs (one per process), frames, recording (default: out/lab)
#   --seats N           seats on this machine (default 3)
#   --first K           number of the first seat (default 1)
#   --prefix P          partition prefix (default lab)
#   --scene FILE        scene every seat runs (default assets/scenes/default.yaml)
#   --trainees          a scripted haptic client per seat (palpate_kidney.traj: 4.5 s, from
#                       its server's first answer: viscera-haptic --start-on-answer);
#                       with --duration S > 0 each palpates over and over (viscera-haptic
#                       --loop) until 1 s before the servers stop (at least one palpation),
#                       so a dashboard or an instructor's command finds them at work; with
#                       --duration 0, once (a script can wait for their summaries)
#   --viewers K         offscreen viewers per seat (default 1; 0 for none)
#   --duration S        seconds the lab runs (default 20; 0: until SIGINT/SIGTERM)
#   --secure            DDS Security on (PKI in --pki DIR)
#   --insecure          allow a network configuration without DDS Security
#                       (prints a warning; anyone on the network can then read
#                       and drive every seat). Without it, a CYCLONEDDS_URI
#                       other than the loopback file needs --secure.
#   --pki DIR           the lab's PKI (default OUT/pki; made by pki.sh when missing)
#   --no-record         no lab recorder
#   --rt-priority N     every server's physics loop SCHED_FIFO at N (1..99; default 0: normal
#                       scheduling); needs root or CAP_SYS_NICE, else each server warns and runs on
#   --haptic-rt-priority N  the same for the trainees' 1 kHz loops (with --trainees)
#   --cpu-wake-latency US  servers and trainees hold a PM QoS bound: no CPU takes
#                       longer than US us (0..10000) to wake from idle while they run
#                       (0: idle CPUs poll; needs root, else each warns and runs on;
#                       README "Wake-up latency")
#   --one-server        every seat in one viscera-server (--seats N --first-seat K),
#                       stepped by one physics thread per CPU: busy seats sharing
#                       cores then step closer to one seat alone, with less CPU
#                       (docs/numerics.md §11.3, §11.4); its log is split
#                       into seatNN-server.log at the end. With --secure its
#                       identity is server-seatKK-MM (pki.sh --server-group K-M:
#                       the server's role in those seats only)
#   --seat-threads K    with --one-server: K physics threads (viscera-server
#                       --seat-threads; default one per CPU, K = --seats: a
#                       thread per seat)
# SIGINT (Ctrl-C) or SIGTERM stops the lab: every process it started gets
# SIGTERM (SIGKILL if still running 10 s later), then the summary is printed.
# Exit status: 0 when every process ended cleanly, 1 when one failed (named
# with its log), 2 on bad usage.
# At start it prints ready-to-paste commands for the instructor's dashboard,
# viscera-control and the report of this lab (with --secure, each with the
# instructor's or recorder's identity in CYCLONEDDS_URI).
# env: VISCERA_DOMAIN (default 0, like every binary), CYCLONEDDS_URI (default the
#   loopback config, like every binary),
#   VISCERA_LAB_STOP_GRACE (seconds before SIGKILL, default 10)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build" OUT="$ROOT/out/lab" SEATS=3 FIRST=1 PREFIX=lab SCENE="$ROOT/assets/scenes/default.yaml"
TRAINEES=0 VIEWERS=1 DURATION=20 SECURE=0 INSECURE=0 RECORD=1 PKI="" RTPRIO=0 HRTPRIO=0 ONE=0 SEATTH="" WAKE=""
STOP_GRACE_S="${VISCERA_LAB_STOP_GRACE:-10}"
usage() { awk 'NR > 2 && /^#/ { sub(/^# ?/, ""); print; next } NR > 2 { exit }' "$0"; }
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
    --insecure) INSECURE=1; shift ;;
    --pki) PKI="$2"; shift 2 ;;
    --no-record) RECORD=0; shift ;;
    --rt-priority) RTPRIO="$2"; shift 2 ;;
    --haptic-rt-priority) HRTPRIO="$2"; shift 2 ;;
    --cpu-wake-latency) WAKE="$2"; shift 2 ;;
    --one-server) ONE=1; shift ;;
    --seat-threads) SEATTH="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "lab.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
done
for v in SEATS FIRST VIEWERS DURATION; do
  [[ "${!v}" =~ ^[0-9]+$ ]] || { echo "lab.sh: --${v,,} must be a whole number" >&2; exit 2; }
done
for v in RTPRIO HRTPRIO; do
  [[ "${!v}" =~ ^[0-9]{1,2}$ ]] ||
    { echo "lab.sh: --$([ $v = RTPRIO ] || echo haptic-)rt-priority must be 0 (normal) or 1..99" >&2; exit 2; }
done
RTPRIO=$((10#$RTPRIO)) HRTPRIO=$((10#$HRTPRIO))
# The option each server / trainee gets (nothing for 0).
SRV_RT=() HAP_RT=()
[ "$RTPRIO" = 0 ] || SRV_RT=(--rt-priority "$RTPRIO")
[ "$HRTPRIO" = 0 ] || HAP_RT=(--rt-priority "$HRTPRIO")
if [ -n "$WAKE" ]; then
  [[ "$WAKE" =~ ^[0-9]{1,5}$ ]] && [ "$((10#$WAKE))" -le 10000 ] ||
    { echo "lab.sh: --cpu-wake-latency must be a number of microseconds 0..10000" >&2; exit 2; }
  SRV_RT+=(--cpu-wake-latency "$((10#$WAKE))") HAP_RT+=(--cpu-wake-latency "$((10#$WAKE))")
fi
[[ "$STOP_GRACE_S" =~ ^[0-9]+$ ]] || { echo "lab.sh: VISCERA_LAB_STOP_GRACE must be a whole number" >&2; exit 2; }
[ "$SEATS" -ge 1 ] && [ "$FIRST" -ge 1 ] && [ $((FIRST + SEATS - 1)) -le 99 ] || { echo "lab.sh: seats must lie in 1..99" >&2; exit 2; }
[[ "$PREFIX" =~ ^[A-Za-z0-9_-]+$ ]] || { echo "lab.sh: --prefix: letters, digits, '-' and '_' only" >&2; exit 2; }
[ -f "$SCENE" ] || { echo "lab.sh: scene file not found: $SCENE" >&2; exit 2; }
[ -x "$BUILD/server/viscera-server" ] || bash "$ROOT/deploy/build.sh" "$BUILD"
GROUPS_OPT=()
if [ -n "$SEATTH" ]; then
  [ $ONE = 1 ] || { echo "lab.sh: --seat-threads needs --one-server" >&2; exit 2; }
  GROUPS_OPT=(--seat-threads "$SEATTH") # the server checks the number
fi
export VISCERA_DOMAIN="${VISCERA_DOMAIN:-0}"
NET="${CYCLONEDDS_URI:-file://$ROOT/deploy/cyclonedds-loopback.xml}"
# Off loopback, secure by default (issue 14): a network configuration runs
# with DDS Security, or only behind an explicit --insecure that says so.
[ $SECURE = 1 ] && [ $INSECURE = 1 ] && { echo "lab.sh: --secure and --insecure exclude each other" >&2; exit 2; }
# shellcheck source=net_guard.sh
source "$ROOT/deploy/net_guard.sh"
# shellcheck source=seat_logs.sh
source "$ROOT/deploy/seat_logs.sh"
net_guard lab.sh "$NET" $SECURE $INSECURE || exit 2
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)" # children get absolute paths
LAST=$((FIRST + SEATS - 1))
PKI="${PKI:-$OUT/pki}"
# The identities' file:// URIs go into the commands printed below, which are
# pasted in other terminals and directories: the path must not be relative.
case "$PKI" in /*) ;; *) PKI="$PWD/$PKI" ;; esac
# One server process for several seats holds one identity, granted the
# server's role in those seats only (pki.sh --server-group).
PKI_ARGS=(--seats "$LAST" --prefix "$PREFIX")
SEATS_ID="server-$(printf 'seat%02d' "$FIRST")"
if [ $ONE = 1 ] && [ "$SEATS" -gt 1 ]; then
  PKI_ARGS+=(--server-group "$FIRST-$LAST")
  SEATS_ID="$(printf 'server-seat%02d-%02d' "$FIRST" "$LAST")"
fi
if [ $SECURE = 1 ] && [ ! -f "$PKI/permissions.p7s" ]; then
  bash "$ROOT/deploy/pki.sh" "$PKI" "${PKI_ARGS[@]}"
fi
as() {
  if [ $SECURE = 0 ]; then echo "$NET"; return; fi
  local f="$PKI/identities/$1/security.xml"
  # A PKI made for fewer seats (or another prefix) lacks the identity: say which.
  [ -f "$f" ] || {
    echo "lab.sh: no identity '$1' in $PKI (make the PKI with pki.sh ${PKI_ARGS[*]}; a lab over several" \
      "machines makes one PKI with every machine's --server-group and copies it to each)" >&2
    return 1
  }
  echo "$NET,file://$f"
}
# With --duration 0 the children run until stopped.
dur() { [ "$DURATION" -gt 0 ] && echo "--duration $(($1))"; true; }

# Every child is started by start() and stays in pids/names until it is
# reaped; nothing else is started, so stop_all() can account for all of them.
pids=() names=() stop_sig=""
running() { # a live, not yet exited process (bash reaps its children by itself)
  local st
  st="$(sed 's/.*) \(.\).*/\1/' "/proc/$1/stat" 2>/dev/null)" || return 1
  [ -n "$st" ] && [ "$st" != Z ]
}
stop_all() {
  local p t left
  for p in "${pids[@]}"; do [ -n "$p" ] && { kill -TERM "$p" 2>/dev/null || true; }; done
  for ((t = 0; t < STOP_GRACE_S * 10; t++)); do
    left=0
    for p in "${pids[@]}"; do [ -n "$p" ] && running "$p" && left=1 && break; done
    [ $left = 0 ] && return 0
    sleep 0.1
  done
  for p in "${pids[@]}"; do
    if [ -n "$p" ] && running "$p"; then
      echo "lab: pid $p still running ${STOP_GRACE_S} s after SIGTERM: SIGKILL" >&2
      kill -KILL "$p" 2>/dev/null || true
    fi
  done
}
on_signal() {
  [ -z "$stop_sig" ] || return 0 # already stopping
  stop_sig="$1"
  echo "lab: $1, stopping every process" >&2
  stop_all
}
trap 'on_signal SIGINT' INT
trap 'on_signal SIGTERM' TERM
trap 'stop_all' EXIT # an error in this script must not leave processes behind
start() { # start NAME IDENTITY COMMAND... : log in OUT/NAME.log
  local name="$1" uri
  uri="$(as "$2")" || exit 1
  shift 2
  [ -z "$stop_sig" ] || return 0
  # The log exists once start() returns: the child opens it only when it
  # runs, and a lab stopped at once (the next identity missing) would kill
  # it before, leaving no log of a process it did start.
  : > "$OUT/$name.log"
  env CYCLONEDDS_URI="$uri" "$@" >> "$OUT/$name.log" 2>&1 &
  pids+=($!) names+=("$name")
}
pause() { # a sleep that SIGINT/SIGTERM cut short
  sleep "$1" &
  local s=$!
  wait $s 2>/dev/null || kill $s 2>/dev/null || true
}

echo "lab: seats $FIRST..$LAST on domain $VISCERA_DOMAIN, partitions $PREFIX/seatNN, $VIEWERS viewer(s) per seat," \
  "secure=$SECURE, $([ "$DURATION" -gt 0 ] && echo "$DURATION s" || echo "until stopped"); output in $OUT"
# Ready-to-paste commands for this lab (the same domain and configuration,
# and the instructor's identity when secure).
paste_env() { # the environment a pasted command needs, as shell words
  local e=""
  [ "$VISCERA_DOMAIN" = 0 ] || e="VISCERA_DOMAIN=$VISCERA_DOMAIN "
  [ "${VISCERA_INSECURE:-0}" != 1 ] || e+="VISCERA_INSECURE=1 " # net_guard allowed it: the programs need it too
  if [ $SECURE = 1 ] || [ -n "${CYCLONEDDS_URI:-}" ]; then
    local u
    u="$(as "$1" 2>/dev/null)" || u="$NET"
    e+="CYCLONEDDS_URI='$u' "
  fi
  printf '%s' "$e"
}
echo "lab: paste these to follow the lab:"
echo "  $(paste_env instructor)$BUILD/client/dashboard/viscera-dashboard --prefix $PREFIX --first $FIRST --seats $SEATS --window"
echo "  $(paste_env instructor)$BUILD/client/dashboard/viscera-dashboard --prefix $PREFIX --first $FIRST --seats $SEATS --out $OUT/dashboard"
echo "  $(paste_env instructor)$BUILD/client/control/viscera-control --partition $PREFIX/$(printf 'seat%02d' "$FIRST") pause"
[ $RECORD = 0 ] || echo "  $BUILD/client/report/viscera-report --out $OUT/report $OUT/lab.db    # after the lab"
if [ $RECORD = 1 ]; then
  rm -f "$OUT/lab.db" "$OUT/lab.db-wal" "$OUT/lab.db-shm"
  # shellcheck disable=SC2046 # dur prints nothing or two words
  start recorder recorder "$BUILD/client/recorder/viscera-recorder" --partition "$PREFIX/*" \
    --out "$OUT/lab.db" --scene "$PREFIX" $(dur DURATION+2) --quiet
fi
if [ $ONE = 1 ]; then
  # shellcheck disable=SC2046
  start seats-server "$SEATS_ID" "$BUILD/server/viscera-server" --scene "$SCENE" \
    --partition "$PREFIX" --seats "$SEATS" --first-seat "$FIRST" $(dur DURATION) "${SRV_RT[@]}" "${GROUPS_OPT[@]}"
fi
for i in $(seq "$FIRST" "$LAST"); do
  s=$(printf 'seat%02d' "$i")
  # shellcheck disable=SC2046
  [ $ONE = 1 ] || start "$s-server" "server-$s" "$BUILD/server/viscera-server" --scene "$SCENE" \
    --partition "$PREFIX/$s" $(dur DURATION) "${SRV_RT[@]}"
  for k in $(seq 1 "$VIEWERS"); do
    rm -rf "$OUT/$s-frames$k"
    # shellcheck disable=SC2046
    start "$s-viewer$k" observer "$BUILD/client/viewer/viscera-viewer" --partition "$PREFIX/$s" \
      --out "$OUT/$s-frames$k" --interval-ms 1000 $(dur DURATION)
  done
done
if [ $TRAINEES = 1 ]; then
  [ -n "$stop_sig" ] || pause 2
  # They start 2 s into the lab and stop 1 s before its servers.
  TRAINEE_RUN=()
  [ "$DURATION" -gt 0 ] && TRAINEE_RUN=(--loop --duration $((DURATION - 3 > 5 ? DURATION - 3 : 5)))
  for i in $(seq "$FIRST" "$LAST"); do
    s=$(printf 'seat%02d' "$i")
    start "$s-haptic" "trainee-$s" "$BUILD/client/haptic/viscera-haptic" --partition "$PREFIX/$s" \
      --trajectory "$ROOT/assets/trajectories/palpate_kidney.traj" --start-on-answer "${TRAINEE_RUN[@]}" --quiet \
      "${HAP_RT[@]}"
  done
fi

# Reap every child with its exit status. A trapped signal cuts a wait short
# while the child still runs: wait again until it is gone, then read the
# status bash kept for it.
failed=0
for i in "${!pids[@]}"; do
  p=${pids[$i]}
  while running "$p"; do wait "$p" 2>/dev/null || true; done
  st=0
  wait "$p" 2>/dev/null || st=$?
  pids[i]=""
  if [ $st != 0 ]; then
    echo "lab: ${names[$i]} (pid $p) exited with status $st; log: $OUT/${names[$i]}.log" >&2
    failed=1
  fi
done
echo "lab: ${stop_sig:+stopped by $stop_sig, }done"
if [ $ONE = 1 ]; then
  split_seat_log "$OUT/seats-server.log" "$OUT" "$PREFIX" server.log # seat_logs.sh
fi
for i in $(seq "$FIRST" "$LAST"); do
  s=$(printf 'seat%02d' "$i")
  peak=$(sed -n 's/.*peak_force=\([0-9.]*\).*/\1/p' "$OUT/$s-haptic.log" 2>/dev/null || true)
  frames=$(cat "$OUT/$s"-frames*/frames.csv 2>/dev/null | grep -c png || true)
  # the step's wall time line (the server's log has further "median" lines since)
  step=$(sed -n 's/^server: [0-9]* steps, \(step time median [0-9.]* us p99 [0-9.]* us\).*/\1/p' "$OUT/$s-server.log" \
    2>/dev/null | tail -1 || true)
  echo "  $s: frames $frames${peak:+, trainee peak force $peak N}${step:+, $step}"
done
if [ $RECORD = 1 ]; then
  "$BUILD/client/recorder/viscera-recinfo" "$OUT/lab.db" | tail -1 | sed 's/^/  recording: /' || true
fi
exit $failed
