#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Damaged recordings never crash or hang a tool (issue 15 item 4).
# usage: damaged_recordings_test.sh BUILD_DIR SOURCE_DIR WORKDIR REC_FLIP
#   1. record a short real session (deploy/session.sh) on $VISCERA_DOMAIN;
#   2. damage copies: NULL or cut type information/mapping, damaged type
#      programs (sqlite3), source times INT64_MAX/INT64_MIN (with and
#      without the session row), one flipped bit of a MeshDelta sim time
#      (rec_flip), an unknown format version;
#   3. run viscera-replay, viscera-resim and viscera-recinfo on each: each
#      must end by itself (a `timeout` of 60 s is only a safety stop; hitting
#      it fails the test), without a signal, with a message naming what is
#      damaged and the documented exit status.
# Before the fix: replay died in dds_create_topic (NULL typemap), recursed or
# looped in the op counter, waited for ever on INT64_MAX; resim planned 17.6
# million steps; recinfo exited 0 on format version 99.
set -u
BUILD=$1
SRC=$2
WORK=$3
FLIP=$4
REPLAY=$BUILD/client/recorder/viscera-replay
RECINFO=$BUILD/client/recorder/viscera-recinfo
RESIM=$BUILD/server/viscera-resim
DOMAIN=${VISCERA_DOMAIN:-193}
OUT_DOMAIN=$((DOMAIN + 1))
fail=0

[ -n "${CYCLONEDDS_URI:-}" ] || { echo "damaged_recordings: CYCLONEDDS_URI is not set" >&2; exit 1; }
command -v sqlite3 >/dev/null || { echo "damaged_recordings: SKIP: no sqlite3 command"; exit 77; }
rm -rf "$WORK"
mkdir -p "$WORK"

echo "== 1. record a session (domain $DOMAIN)"
VISCERA_PARTITION=hardinput/damaged bash "$SRC/deploy/session.sh" "$BUILD" "$WORK/session" \
  >"$WORK/session.log" 2>&1 || { cat "$WORK/session.log"; echo "FAIL: session.sh"; exit 1; }
DB=$WORK/session/session.db

# run NAME WANT_RC PATTERN CMD...: the command ends within the safety stop,
# without a signal, with an exit status matching WANT_RC (a regex) and PATTERN in its output.
run() {
  local name=$1 want=$2 pat=$3
  shift 3
  timeout -k 5 60 "$@" >"$WORK/$name.out" 2>&1
  local rc=$?
  if [ $rc -eq 124 ] || [ $rc -eq 137 ]; then
    echo "FAIL $name: still running after 60 s (hang)"; tail -n 5 "$WORK/$name.out"; fail=1; return
  fi
  if [ $rc -ge 128 ] || grep -q "Sanitizer" "$WORK/$name.out"; then
    echo "FAIL $name: crashed (status $rc)"; tail -n 20 "$WORK/$name.out"; fail=1; return
  fi
  if ! [[ "$rc" =~ ^($want)$ ]] || ! grep -qE -- "$pat" "$WORK/$name.out"; then
    echo "FAIL $name: status $rc (want $want), '$pat' expected in:"; tail -n 10 "$WORK/$name.out"; fail=1; return
  fi
  echo "ok   $name: status $rc: $(grep -E -m1 -- "$pat" "$WORK/$name.out")"
}
damaged() { # damaged NAME SQL: a copy of the recording with SQL applied
  cp "$DB" "$WORK/$1.db"
  sqlite3 "$WORK/$1.db" "$2" || { echo "FAIL $1: cannot prepare"; fail=1; }
}
RP=(--domain "$OUT_DOMAIN" --partition hardinput/out --speed 20 --quiet)

echo "== 2. stored type descriptors"
TC="WHERE name = 'viscera_ToolCommand'"
damaged ti_null "UPDATE topics SET typeinfo = NULL $TC"
run ti_null 1 "NOT replayed: topic viscera_ToolCommand: stored type information is damaged" "$REPLAY" "$WORK/ti_null.db" "${RP[@]}"
damaged tm_null "UPDATE topics SET typemap = NULL $TC"
run tm_null 1 "NOT replayed: topic viscera_ToolCommand: stored type information is damaged" "$REPLAY" "$WORK/tm_null.db" "${RP[@]}"
damaged tm_cut "UPDATE topics SET typemap = substr(typemap, 1, 300) $TC"
run tm_cut 1 "viscera_ToolCommand: stored type information is damaged: type mapping unreadable" "$REPLAY" "$WORK/tm_cut.db" "${RP[@]}"
damaged tm_other "UPDATE topics SET typemap = (SELECT typemap FROM topics WHERE name = 'viscera_Metrics') $TC"
run tm_other 1 "viscera_ToolCommand: stored type information is damaged: the minimal type is not in the type mapping" \
  "$REPLAY" "$WORK/tm_other.db" "${RP[@]}"
# A sequence of structs whose element program is the member itself (ADR SEQ
# STU, offset 0, 16 bytes, jump 4 / element +0): Cyclone's op counter
# recursed into it without end.
damaged ops_self "UPDATE topics SET ops = x'000A07010000000010000000'
  || x'00000400' || substr(ops, 17) $TC"
run ops_self 1 "viscera_ToolCommand: stored type program is damaged" "$REPLAY" "$WORK/ops_self.db" "${RP[@]}"
damaged ops_zero "UPDATE topics SET ops = zeroblob(length(ops)) $TC"
run ops_zero 1 "viscera_ToolCommand: stored type program is damaged" "$REPLAY" "$WORK/ops_zero.db" "${RP[@]}"
damaged ops_junk "UPDATE topics SET ops = substr(x'$(printf 'ba1c4db1%.0s' $(seq 1 40))', 1, length(ops)) $TC"
run ops_junk 1 "viscera_ToolCommand: stored type program is damaged: op 0" "$REPLAY" "$WORK/ops_junk.db" "${RP[@]}"

echo "== 3. source times outside the recording"
ROW="(SELECT id FROM samples WHERE kind = 0 ORDER BY id LIMIT 1 OFFSET 100)"
damaged ts_max "UPDATE samples SET source_ts_ns = 9223372036854775807 WHERE id = $ROW"
run ts_max 1 "outside the recording's span" "$REPLAY" "$WORK/ts_max.db" "${RP[@]}"
damaged ts_min "UPDATE samples SET source_ts_ns = -9223372036854775808 WHERE id = $ROW"
run ts_min 1 "outside the recording's span" "$REPLAY" "$WORK/ts_min.db" "${RP[@]}"
damaged ts_max_nosession "DELETE FROM session; UPDATE samples SET source_ts_ns = 9223372036854775807 WHERE id = $ROW"
run ts_max_nosession 1 "outside the recording's span" "$REPLAY" "$WORK/ts_max_nosession.db" "${RP[@]}"
damaged ts_min_nosession "DELETE FROM session; UPDATE samples SET source_ts_ns = -9223372036854775808 WHERE id = $ROW"
run ts_min_nosession 1 "outside the recording's span" "$REPLAY" "$WORK/ts_min_nosession.db" "${RP[@]}"

echo "== 4. one flipped bit in a MeshDelta header"
# MeshDelta CDR (XCDR2, @appendable): 4-byte header, DHEADER, organ_id,
# topology_version, keyframe_seq, frame_seq, then sim_time_ns (little-endian,
# aligned to 4) at bytes 24..31: byte 29 bit 4 is bit 44 of the time, +17,592 s.
cp "$DB" "$WORK/flip.db"
"$FLIP" "$WORK/flip.db" viscera_MeshDelta 10 29 16 || fail=1
run resim_flip_reported "0|1" "beyond the recording" "$RESIM" --scene "$SRC/assets/scenes/default.yaml" \
  "$WORK/flip.db" --quiet
steps=$(sed -n 's/^RESIM [A-Z]* steps=\([0-9]*\).*/\1/p' "$WORK/resim_flip_reported.out")
if [ -z "$steps" ] || [ "$steps" -gt 20000 ]; then
  echo "FAIL resim_flip: planned '${steps}' steps for a recording of a few seconds"; fail=1
else
  echo "ok   resim_flip: $steps steps"
fi

echo "== 5. unknown format version"
damaged v99 "PRAGMA user_version = 99"
run recinfo_v99 1 "format version 99 is not one this tool reads" "$RECINFO" "$WORK/v99.db"
damaged v7 "UPDATE session SET format_version = 7"
run recinfo_v7 1 "format version 7 \\(session row\\) is not one this tool reads" "$RECINFO" "$WORK/v7.db"
run replay_v7 1 "format version 7" "$REPLAY" "$WORK/v7.db" "${RP[@]}"
run resim_v7 2 "format version 7" "$RESIM" --scene "$SRC/assets/scenes/default.yaml" "$WORK/v7.db" --quiet

echo "== 6. 64 KB zeroed in the middle of the file: inputs in the damaged part"
# Sample pages (rows of every topic, in recording order) are lost there and
# read again after it: AppliedInputs are missing in between, and resim blames
# the damage it has just reported, not the recorder.
cp "$DB" "$WORK/zeroed.db"
dd if=/dev/zero of="$WORK/zeroed.db" bs=1 seek=$(($(stat -c %s "$DB") * 2 / 5)) count=65536 conv=notrunc status=none
run resim_zeroed 1 "missing from the recording \(in the damaged part of the file" "$RESIM" \
  --scene "$SRC/assets/scenes/default.yaml" "$WORK/zeroed.db" --quiet

[ $fail -eq 0 ] && echo "damaged_recordings: PASS"
exit $fail
