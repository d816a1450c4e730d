#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The commands deploy/lab.sh prints at start are pasted as printed, in
# another terminal and another directory, as the README says to: a secure
# lab whose PKI was given by a relative path (--pki pki, as the README's
# "Classroom and remote sessions" block gives out/pki) must still print
# commands that work from anywhere. Runs lab.sh --secure with one seat from
# a scratch directory, then from / the printed dashboard (--out) and
# viscera-control lines: the control is answered "applied" (exit 0), the
# dashboard sees the seat's scene (have_scene 1 in its CSV). Before the fix
# the identity's file:// URI was relative and both refused to start.
# usage: lab_paste_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
# shellcheck source=lab_checks.sh
. "$(dirname "$0")/lab_checks.sh"
L=""
cleanup() { [ -z "$L" ] || kill -TERM "$L" 2>/dev/null || true; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  for f in "$OUT"/*.out "$OUT"/*.log "$OUT"/run/lab/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -6 "$f"; }; done >&2
  exit 1
}
rm -rf "$OUT"; mkdir -p "$OUT/run"
command -v openssl > /dev/null || fail "openssl missing (deploy/install_deps.sh installs it)"

# Started from OUT/run with relative --out and --pki, as a user in the
# repository root pastes the README's block.
cd "$OUT/run"
launch_lab L "$OUT/lab.out" --out lab --pki pki --seats 1 --viewers 0 --no-record --secure --duration 0
cd /
for ((t = 0; t < 600; t++)); do
  grep -q 'viscera-control --partition' "$OUT/lab.out" 2>/dev/null && break
  kill -0 "$L" 2>/dev/null || fail "lab.sh ended before printing its commands"
  sleep 0.1
done
CONTROL="$(sed -n 's/^  \(.*viscera-control --partition .*\)$/\1/p' "$OUT/lab.out")"
DASH="$(sed -n 's/^  \(.*viscera-dashboard .* --out .*\)$/\1/p' "$OUT/lab.out")"
[ -n "$CONTROL" ] && [ -n "$DASH" ] || fail "lab.sh printed no control or dashboard command"
echo "printed: $CONTROL"

# Pasted in / (another terminal's directory). The server may still be
# starting: viscera-control waits up to --wait for it (default suffices).
st=0
(cd / && eval "$CONTROL") > "$OUT/control.log" 2>&1 || st=$?
cat "$OUT/control.log"
[ $st = 0 ] || fail "the printed viscera-control line, pasted in /, exited $st"
grep -q '^applied: paused' "$OUT/control.log" || fail "the printed control was not applied"
st=0
(cd / && eval "$DASH --duration 4") > "$OUT/dashboard.log" 2>&1 || st=$?
[ $st = 0 ] || fail "the printed dashboard line, pasted in /, exited $st"
CSV="$OUT/run/lab/dashboard/dashboard.csv"
[ -f "$CSV" ] || fail "the pasted dashboard wrote no $CSV"
awk -F, 'NR > 1 && $3 == "lab/seat01" && $4 == 1 { ok = 1 } END { exit !ok }' "$CSV" ||
  fail "the pasted dashboard never saw seat 1's scene"

kill -INT "$L"
st=0
for ((t = 0; t < 300; t++)); do kill -0 "$L" 2>/dev/null || break; sleep 0.1; done
wait "$L" || st=$?
[ $st = 0 ] || fail "lab.sh exited $st after SIGINT"
expect_nothing_left "$L" "lab.sh"
L=""
echo PASS
