#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Palpation thresholds end to end: a whole session (server, recorder, viewer,
# scripted haptic client) on the default scene, whose probe has
# thresholds {st: 0.5, mpf: 0.8, sft: 1.5}; the scripted 8 mm press holds
# about 0.97 N. The shell only runs the session; rec_palpation asserts in C
# over the recorded SessionEvents, Metrics and ToolMetrics: an upward and a
# downward crossing of ST and MPF and none of SFT; the last Metrics has time
# above ST and MPF > 0 (ST >= MPF), none above SFT, contact time, mean
# contact force and path length in range; the server's own tracker (its
# ToolMetrics) agrees; a reader meeting a sample that does not decode fails
# naming it. usage: palpation_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log "$OUT"/*.out; do echo "--- $f"; tail -5 "$f"; done >&2; exit 1; }

VIEWER_ARGS="--interval-ms 500" bash "$SRC/deploy/session.sh" "$BUILD" "$OUT" || fail "session did not run"

# Every check is in C over the recorded samples (rec_palpation.c).
"$BUILD/tests/integration/rec_palpation" "$OUT/session.db" || fail "palpation checks failed (above)"

# Negative control: one Metrics sample truncated in a copy; the reader
# (rec_read.c) must meet exactly that one undecodable sample, not salvage it.
cp "$OUT/session.db" "$OUT/garbled.db"
sqlite3 "$OUT/garbled.db" "UPDATE samples SET cdr = X'0001000001' WHERE id = (SELECT s.id FROM samples s
  JOIN topics t ON t.id = s.topic_id WHERE t.name = 'viscera_Metrics' AND s.kind = 0 ORDER BY s.id LIMIT 1)"
"$BUILD/tests/integration/rec_palpation" --expect-undecodable viscera_Metrics 1 "$OUT/garbled.db" ||
  fail "undecodable sample not reported as one bad viscera_Metrics sample"
echo "PASS"
