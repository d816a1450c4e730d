#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The service units in deploy/systemd/ (issue 7), without installing them:
#   1. `systemd-analyze verify` accepts copies of them whose paths point into
#      the build tree (ExecStart binaries resolvable) and the test directory:
#      exit 0 and not one warning about them (verify only warns about unknown
#      keys or bad values, so a warning fails the test). verify needs no
#      running systemd: it works in a container whose PID 1 is something else;
#   2. every --option an ExecStart passes is in that binary's --help;
#   3. the ExecStart lines do what the units promise, run the way systemd
#      runs them (EnvironmentFile read, %i and %% expanded, ${VAR} replaced
#      as one word; User= and the sandboxing options are not applied) for
#      instance seat01 on domain 164: the server serves PARTITION from the
#      env file, the recorder records it into STATE/seat01-<UTC time>.db, and
#      SIGTERM (what `systemctl stop` sends) ends both cleanly; the server
#      leaves its checkpoint in the state directory;
#   4. the seats unit (viscera-seats@lab: --seats from the env file) serves
#      both seats in one process and leaves a checkpoint per seat.
# Exit 77 (skipped) only when systemd-analyze is not installed.
# usage: systemd_units_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -6 "$f"; }; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT/units" "$OUT/etc" "$OUT/state"
if ! command -v systemd-analyze > /dev/null; then
  echo "SKIP: systemd-analyze not installed (Debian package systemd; deploy/install_deps.sh installs it)"
  exit 77
fi
UNITS=("$SRC"/deploy/systemd/*.service)
[ ${#UNITS[@]} -ge 2 ] || fail "no service units in deploy/systemd"

# Where each /usr/local/bin/NAME of the units is in the build tree.
built() {
  local f
  f=$(find "$BUILD" -name "$1" -type f -perm -u+x -print -quit)
  [ -n "$f" ] || fail "ExecStart binary $1 not built in $BUILD"
  echo "$f"
}
for u in "${UNITS[@]}"; do
  copy="$OUT/units/$(basename "$u")"
  cp "$u" "$copy"
  for name in $(grep -o '/usr/local/bin/[A-Za-z0-9_-]*' "$u" | sort -u | sed 's|.*/||'); do
    path=$(built "$name")
    sed -i "s|/usr/local/bin/$name\b|$path|g" "$copy"
  done
  sed -i "s|/etc/viscera/|$OUT/etc/|g; s|/var/lib/viscera/|$OUT/state/|g" "$copy"
done

# 1. systemd-analyze verify.
if ! systemd-analyze verify --man=no "$OUT"/units/*.service > "$OUT/verify.log" 2>&1; then
  fail "systemd-analyze verify failed: $(cat "$OUT/verify.log")"
fi
if grep -q -e 'viscera' -e "$OUT" "$OUT/verify.log"; then
  fail "systemd-analyze verify warns about the units: $(cat "$OUT/verify.log")"
fi
[ -s "$OUT/verify.log" ] && echo "note, systemd-analyze on other units: $(cat "$OUT/verify.log")"
echo "systemd-analyze verify: ${#UNITS[@]} units accepted ($(systemd-analyze --version | head -1))"

# 2. Options against --help.
execs() { sed -n 's/^ExecStart=//p' "$1"; }
for u in "${UNITS[@]}"; do
  line=$(execs "$u")
  [ -n "$line" ] || fail "$(basename "$u") has no ExecStart"
  names=$(grep -o '/usr/local/bin/[A-Za-z0-9_-]*' <<< "$line" | sort -u)
  [ "$(wc -l <<< "$names")" = 1 ] || fail "$(basename "$u"): expected one viscera binary in ExecStart"
  bin=$(built "${names##*/}")
  help=$("$bin" --help 2>&1) || fail "$bin --help failed"
  for opt in $(grep -oE -- '--[a-z][a-z-]*' <<< "$line" | sort -u); do
    grep -qE -- "(^|[ ,])$opt( |=|$)" <<< "$help" || fail "$(basename "$u"): $opt not in ${names##*/} --help"
    echo "  $(basename "$u"): ${names##*/} $opt: in --help"
  done
done

# 3. The ExecStart lines run as systemd would run them, instance seat01.
cat > "$OUT/etc/seat01.env" << EOF
SCENE=$SRC/assets/scenes/default.yaml
PARTITION=unit/seat01
VISCERA_DOMAIN=${VISCERA_DOMAIN:?domain expected}
CYCLONEDDS_URI=${CYCLONEDDS_URI:?loopback config expected}
EOF
run_unit() { # run_unit COPY INSTANCE LOG: ExecStart in the background, pid in UNIT_PID
  local line env
  line=$(execs "$1")
  env=$(sed -n 's/^EnvironmentFile=//p' "$1")
  line=${line//%i/$2}
  line=${line//%%/%}
  # systemd replaces ${VAR} by its value as one word: quote it for eval.
  line=$(sed -E 's/\$\{([A-Za-z_][A-Za-z0-9_]*)\}/"${\1}"/g' <<< "$line")
  env=${env//%i/$2}
  (
    set -a
    # shellcheck disable=SC1090
    . "$env"
    set +a
    eval "exec $line"
  ) > "$3" 2>&1 &
  UNIT_PID=$!
}
run_unit "$OUT/units/viscera-server@.service" seat01 "$OUT/server.log"
SRV_PID=$UNIT_PID
PIDS+=("$SRV_PID")
sleep 0.5
run_unit "$OUT/units/viscera-recorder@.service" seat01 "$OUT/recorder.log"
REC_PID=$UNIT_PID
PIDS+=("$REC_PID")
sleep 4
kill -0 "$SRV_PID" 2>/dev/null || fail "the server unit's command exited early"
kill -0 "$REC_PID" 2>/dev/null || fail "the recorder unit's command exited early"
kill -TERM "$REC_PID"
wait "$REC_PID" || fail "the recorder unit's command did not stop cleanly on SIGTERM"
kill -TERM "$SRV_PID"
wait "$SRV_PID" || fail "the server unit's command did not stop cleanly on SIGTERM"
PIDS=()
grep -q "running on domain $VISCERA_DOMAIN, partition 'unit/seat01'" "$OUT/server.log" \
  || fail "the server did not take its domain and partition from the env file"
dbs=("$OUT"/state/seat01-*.db)
[ -f "${dbs[0]}" ] || fail "no recording in the state directory"
[[ "$(basename "${dbs[0]}")" =~ ^seat01-[0-9]{8}T[0-9]{6}Z\.db$ ]] || fail "recording name ${dbs[0]} not seat01-<UTC time>.db"
read -r scene part closed < <(sqlite3 -separator ' ' "${dbs[0]}" "SELECT scene, partition, end_wall_ns IS NOT NULL FROM session")
deltas=$(sqlite3 "${dbs[0]}" "SELECT count(*) FROM samples s JOIN topics t ON t.id = s.topic_id WHERE t.name = 'viscera_MeshDelta'")
echo "recorder unit: $(basename "${dbs[0]}"), scene '$scene', partition '$part', $deltas MeshDelta samples"
[ "$scene" = seat01 ] && [ "$part" = unit/seat01 ] || fail "recording metadata: scene '$scene', partition '$part'"
[ "$closed" = 1 ] || fail "the recording has no end time"
[ "${deltas:-0}" -gt 10 ] || fail "the recorder unit recorded ${deltas:-0} MeshDelta samples"
[ -s "$OUT/state/seat01.ckpt" ] || fail "the server unit wrote no checkpoint into its state directory"

# 4. The seats unit, instance lab: one process serving unit/seat02 and
# unit/seat03 from the env file, a checkpoint per seat in the state directory.
cat > "$OUT/etc/lab.env" << EOF
SCENE=$SRC/assets/scenes/default.yaml
PREFIX=unit
SEATS=2
FIRST=2
VISCERA_DOMAIN=$VISCERA_DOMAIN
CYCLONEDDS_URI=$CYCLONEDDS_URI
EOF
run_unit "$OUT/units/viscera-seats@.service" lab "$OUT/seats.log"
PIDS+=("$UNIT_PID")
sleep 3
kill -0 "$UNIT_PID" 2>/dev/null || fail "the seats unit's command exited early"
kill -TERM "$UNIT_PID"
wait "$UNIT_PID" || fail "the seats unit's command did not stop cleanly on SIGTERM"
PIDS=()
for s in seat02 seat03; do
  grep -q "^server unit/$s: scene .* running on domain $VISCERA_DOMAIN, partition 'unit/$s'" "$OUT/seats.log" ||
    fail "the seats unit did not serve unit/$s"
  [ -s "$OUT/state/lab.ckpt.$s" ] || fail "the seats unit wrote no checkpoint lab.ckpt.$s into its state directory"
done
echo "seats unit: unit/seat02 and unit/seat03 in one process, a checkpoint each"
echo PASS
