# SPDX-License-Identifier: Apache-2.0
# prelude.sh: what every integration test script starts with, sourced right
# after `set -euo pipefail`:
#   BUILD, SRC, OUT   the build tree, the source tree and the test's output
#                     directory (the arguments the test macro passes; OUT is
#                     emptied)
#   PIDS              processes to kill -9 when the script exits, however it exits
#   fail MSG          prints MSG and the last FAIL_TAIL (default 6) lines of each
#                     OUT/*.log and of the files FAIL_LOGS names (a glob), exits 1
BUILD="$1"; SRC="$2"; OUT="$3"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  # FAIL_LOGS is a glob on purpose: expanded here, when the files exist.
  # shellcheck disable=SC2086
  for f in "$OUT"/*.log ${FAIL_LOGS:-}; do
    [ -e "$f" ] || continue
    echo "--- $f"; tail -"${FAIL_TAIL:-6}" "$f"
  done >&2
  exit 1
}
rm -rf "$OUT"; mkdir -p "$OUT"
