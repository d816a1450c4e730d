#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# deploy/session.sh (and demo.sh, which calls it) when a process fails, as a user
# meets it: a scene with one wrong field, whose server stops at once, a
# trajectory that does not exist, and viewer options the viewer refuses (no
# frames). Each run must end with a non-zero status and
# say on stderr which process failed, which log to read and the process's own
# message (file, line and field for the scene), not exit silently.
# usage: session_failures_test.sh BUILD SRC OUT
set -uo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
export VISCERA_DOMAIN="${VISCERA_DOMAIN:-199}"
rm -rf "$OUT"; mkdir -p "$OUT"
failures=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }

# 1. One wrong field: the organ's stiffness negative.
sed 's/stiffness: 30,/stiffness: -30,/' "$SRC/assets/scenes/stone_removal.yaml" >"$OUT/wrong_field.yaml"
line=$(grep -n 'stiffness: -30,' "$OUT/wrong_field.yaml" | head -1 | cut -d: -f1)
bash "$SRC/deploy/session.sh" "$BUILD" "$OUT/s1" "$OUT/wrong_field.yaml" \
  "$SRC/assets/trajectories/palpate_kidney.traj" >"$OUT/s1.out" 2>"$OUT/s1.err"
rc=$?
[ $rc -ne 0 ] || fail "wrong field: session.sh exit status 0"
grep -q "server exited (see $OUT/s1/server.log)" "$OUT/s1.err" || fail "wrong field: stderr does not name the server's log"
grep -q "wrong_field.yaml:$line: field 'organs\[0\].material.stiffness'" "$OUT/s1.err" ||
  fail "wrong field: stderr does not carry the server's message (file:$line and field)"
echo "wrong field: status $rc"; cat "$OUT/s1.err"

# 2. The trajectory is missing: the haptic client fails with the server up.
bash "$SRC/deploy/session.sh" "$BUILD" "$OUT/s2" "$SRC/assets/scenes/default.yaml" \
  "$OUT/no_such.traj" >"$OUT/s2.out" 2>"$OUT/s2.err"
rc=$?
[ $rc -ne 0 ] || fail "missing trajectory: session.sh exit status 0"
grep -q "haptic client failed, status [1-9].* (see $OUT/s2/haptic.log)" "$OUT/s2.err" ||
  fail "missing trajectory: stderr does not name the haptic client's log"
grep -q "no_such.traj: cannot open" "$OUT/s2.err" || fail "missing trajectory: stderr does not carry the client's message"
grep -q "server exited" "$OUT/s2.err" && fail "missing trajectory: blames the server, which was running"
echo "missing trajectory: status $rc"; cat "$OUT/s2.err"

# 3. The viewer refuses its options (VIEWER_ARGS): no frames would be written.
VIEWER_ARGS="--width 99999" bash "$SRC/deploy/session.sh" "$BUILD" "$OUT/s3" "$SRC/assets/scenes/default.yaml" \
  "$SRC/assets/trajectories/palpate_kidney.traj" >"$OUT/s3.out" 2>"$OUT/s3.err"
rc=$?
[ $rc -ne 0 ] || fail "viewer options: session.sh exit status 0 without a viewer"
grep -q "the viewer exited (see $OUT/s3/viewer.log)" "$OUT/s3.err" || fail "viewer options: stderr does not name the viewer's log"
grep -q -- "--width '99999'" "$OUT/s3.err" || fail "viewer options: stderr does not carry the viewer's message"
echo "viewer options: status $rc"; cat "$OUT/s3.err"

[ $failures -eq 0 ] && echo PASS || { echo "$failures check(s) failed"; exit 1; }
