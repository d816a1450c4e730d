#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Schema evolution (issue 16 item 5): the recordings kept in tests/data
# (tests/data/README.md) must be read, re-simulated and reported by every
# later build. For each: viscera-resim from the recording alone (its meshes
# found by digest in assets/meshes) re-simulates every recorded input
# (INPUTS mode=applied with the recorded command count) and compares every
# frame (ORGAN line with the recorded frame count) and ToolMetrics sample,
# and, for a resumed session, starts from its recorded resume state; exiting
# 0 (reproduced) or 1 (another build or physics: the errors are
# reported against the recording), never 2 (unreadable); viscera-recinfo
# lists it and viscera-report reports it (exit 0).
# usage: resim_format_test.sh BUILD SRC OUT
set -uo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
rm -rf "$OUT"; mkdir -p "$OUT"
fail() { echo "FAIL: $*" >&2; exit 1; }
# recording  commands  frames(kidney)  toolmetrics  [resumed: the step it resumed at]
while read -r rec commands frames metrics resumed; do
  db="$SRC/tests/data/$rec"
  [ -f "$db" ] || fail "$db missing"
  "$BUILD/server/viscera-resim" "$db" --mesh-dir "$SRC/assets/meshes" --quiet >"$OUT/$rec.resim" 2>"$OUT/$rec.log"
  rc=$?
  cat "$OUT/$rec.resim" "$OUT/$rec.log"
  [ $rc -eq 0 ] || [ $rc -eq 1 ] || fail "$rec: viscera-resim exit $rc (not readable)"
  grep -q "^SCENE source=recording " "$OUT/$rec.resim" || fail "$rec: the scene was not taken from the recording"
  grep -q "^INPUTS mode=applied commands=$commands " "$OUT/$rec.resim" || fail "$rec: not $commands applied commands"
  grep -q "^ORGAN kidney frames=$frames " "$OUT/$rec.resim" || fail "$rec: not $frames frames compared"
  grep -q "^TOOLMETRICS compared=$metrics " "$OUT/$rec.resim" || fail "$rec: not $metrics ToolMetrics compared"
  grep -q "^RESIM \(PASS\|FAIL\) " "$OUT/$rec.resim" || fail "$rec: no RESIM line"
  if [ -n "$resumed" ]; then
    grep -q "^RESUMED step=$resumed " "$OUT/$rec.resim" || fail "$rec: not started from its recorded resume state"
  fi
  "$BUILD/client/recorder/viscera-recinfo" "$db" >"$OUT/$rec.info" 2>&1 || fail "$rec: viscera-recinfo failed"
  grep -q "station=trainee1" "$OUT/$rec.info" || fail "$rec: the trainee's station is not listed"
  if [ -x "$BUILD/client/report/viscera-report" ]; then
    "$BUILD/client/report/viscera-report" --out "$OUT/$rec.report" "$db" >"$OUT/$rec.report.log" 2>&1 ||
      fail "$rec: viscera-report failed: $(tail -3 "$OUT/$rec.report.log")"
  fi
  echo "ok   $rec"
done <<'LIST'
session_applied_xcdr1.db 251 75 3
session_resumed_format2.db 968 52 1 3000
session_appendable_format3.db 250 92 4
LIST
echo PASS
