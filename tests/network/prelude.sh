# SPDX-License-Identifier: Apache-2.0
# prelude.sh: what every network test script starts with, sourced right after
# `set -euo pipefail` (arguments BUILD SRC OUT as ctest passes them):
#   BUILD, SRC, OUT   build tree, source tree, the test's output directory (emptied)
#   PIDS              processes to kill -9 when the script exits
#   fail MSG          prints MSG and the tail of every OUT/*.log, exits 1
#   the sites.sh functions; exits 77 (skip) where sites cannot be made.
# At exit: PIDS killed, then the sites (namespaces, veths, emulator) removed.
BUILD="$1"; SRC="$2"; OUT="$3"
PIDS=()
# shellcheck source=sites.sh
source "$SRC/tests/network/sites.sh"
export LINK_EMU="$BUILD/tests/network/link_emu"
sites_require || exit $?
net_cleanup() {
  for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  sites_down quiet
}
fail() {
  echo "FAIL: $*" >&2
  for f in "$OUT"/*.log; do
    [ -e "$f" ] || continue
    echo "--- $f"; tail -"${FAIL_TAIL:-6}" "$f"
  done >&2
  exit 1
}
rm -rf "$OUT"; mkdir -p "$OUT"
# net_sites PFX: the two sites, removed at exit whatever happens.
net_sites() {
  sites_up "$1" "$OUT" || fail "could not make the sites"
  trap net_cleanup EXIT
}
# A key=value field from a SUMMARY-style line of FILE: field FILE KEY.
field() { sed -n "s/.*[ :]$2=\([-0-9.e+]*\).*/\1/p" "$1" | tail -1; }
