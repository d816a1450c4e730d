#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# cli_binaries_test.sh VERSION BAD_STATUS BINARY NAME: one program answers the
# options every viscera program shares (common/cli.c): --version prints
# exactly "NAME VERSION" (cmake/version.cmake) and exits 0; -h and --help
# print the same usage text on stdout, listing the exit codes, and exit 0; an unknown option exits with the program's usage status
# (BAD_STATUS) and writes nothing on stdout.
set -uo pipefail
VERSION="$1" BAD="$2" BIN="$3" NAME="$4"
fail() { echo "FAIL: $NAME: $*"; exit 1; }
out="$("$BIN" --version)"; rc=$?
[ "$rc" = 0 ] || fail "--version exited $rc"
[ "$out" = "$NAME $VERSION" ] || fail "--version printed '$out', expected '$NAME $VERSION'"
out="$("$BIN" --help)"; rc=$?
[ "$rc" = 0 ] || fail "--help exited $rc"
echo "$out" | grep -qi 'usage' || fail "--help printed no usage text"
echo "$out" | grep -qi '^exit' || fail "--help does not list the exit codes (a line starting 'exit')"
short="$("$BIN" -h)"; rc=$?
[ "$rc" = 0 ] || fail "-h exited $rc"
[ "$short" = "$out" ] || fail "-h and --help print different texts"
out="$("$BIN" --no-such-option 2>/dev/null)"; rc=$?
[ "$rc" = "$BAD" ] || fail "an unknown option exited $rc, expected $BAD"
[ -z "$out" ] || fail "an unknown option wrote on stdout: $out"
echo "ok: $NAME --version, --help, unknown option ($BAD)"
