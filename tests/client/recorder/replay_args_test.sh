#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-replay refuses an out-of-range --speed, --seek or --pause-at before it
# opens anything, with exit 1 and a message that states the range the value
# broke: "--speed 1e9" once said "expected a number > 0", which 1e9 is.
# usage: replay_args_test.sh REPLAY
set -uo pipefail
REPLAY="$1"
fail() { echo "FAIL: $*"; exit 1; }
check() { # check 'ARGS' 'EXPECTED TEXT'
  local err rc
  # shellcheck disable=SC2086 # ARGS is a list of words on purpose
  err=$("$REPLAY" /nonexistent.db $1 2>&1 >/dev/null); rc=$?
  echo "$1: exit $rc: $err"
  [ $rc -eq 1 ] || fail "$1: exit $rc, want 1"
  echo "$err" | grep -qF -- "$2" || fail "$1: message '$err' does not say '$2'"
}
check "--speed 1e9" "expected a number > 0 and at most 1e6"
check "--speed 0" "expected a number > 0 and at most 1e6"
check "--seek 1e9" "expected seconds, 0 to 1e8"
check "--seek -1" "expected seconds, 0 to 1e8"
check "--pause-at 2e8" "expected seconds, 0 to 1e8"
echo PASS
