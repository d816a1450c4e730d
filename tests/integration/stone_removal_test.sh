#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Kidney-stone removal over DDS (docs/methods.md A, issue 4): two scripted clients,
# the probe (tool 0) palpates the spot of the palpate_target task, the
# extractor (tool 1) goes in, closes on the stone, carries it out, opens.
# Asserts from the recording: GRASP_BEGIN/END of the stone, TASK_COMPLETED
# of remove-stone with an operation time, the last ObjectState has the stone
# outside (removed, above the kidney's 3.5 cm top); the probe's find-spot
# task completed (exploration time in its ToolMetrics); the server's TASK
# and OBJECT lines agree; the viewer wrote frames.
# usage: stone_removal_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log "$OUT"/*.out; do echo "--- $f"; tail -5 "$f"; done >&2; exit 1; }
. "$(dirname "$0")/tools_session.sh"
tools_session "$BUILD" "$OUT" "$SRC/assets/scenes/stone_removal.yaml" \
  "0:$SRC/assets/trajectories/palpate_kidney.traj" "1:$SRC/assets/trajectories/stone_removal_extractor.traj" \
  || fail "session did not run"

# The checks are rec_tools --expect stone_removal (rec_tools.c): over the
# recording, and the server's TASK and OBJECT lines.
"$BUILD/tests/integration/rec_tools" "$OUT/session.db" --expect stone_removal --server-out "$OUT/server.out" \
  > "$OUT/rec.txt" || { cat "$OUT/rec.txt"; fail "rec_tools: a check failed (above)"; }
cat "$OUT/rec.txt"
ls "$OUT"/frames/*.png >/dev/null 2>&1 || fail "viewer wrote no frames"
echo "PASS"
