#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Grasp, hold, pull, release over DDS (issue 4): a scripted grasper closes
# its jaws (buttons column) on the top of the kidney, lifts 12 mm, holds,
# opens. Asserts from the recording (decoded CDR): a GRASP_BEGIN and a
# GRASP_END event, the grasp_pull task completed with its operation time;
# the kidney vertex under the jaws rose > 5 mm in the MeshDeltas while held
# and is back within 0.5 mm at the end; the haptic client rendered a
# downward pull (> 0.5 N) while held; ToolMetrics and the server's TOOL line
# agree. Opens a viewer frame of the lift for a human (see HANDOFF).
# usage: grasp_pull_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log "$OUT"/*.out; do echo "--- $f"; tail -5 "$f"; done >&2; exit 1; }
. "$(dirname "$0")/tools_session.sh"
tools_session "$BUILD" "$OUT" "$SRC/assets/scenes/grasp_pull.yaml" \
  "0:$SRC/assets/trajectories/grasp_pull_kidney.traj" || fail "session did not run"

# The checks are rec_tools --expect grasp_pull (rec_tools.c): over the
# recording, the haptic client's force CSV and the server's TASK line.
"$BUILD/tests/integration/rec_tools" "$OUT/session.db" --vertex 0.012 0.004 0.0346 --expect grasp_pull \
  --haptic-csv "$OUT/haptic0.csv" --server-out "$OUT/server.out" > "$OUT/rec.txt" \
  || { cat "$OUT/rec.txt"; fail "rec_tools: a check failed (above)"; }
cat "$OUT/rec.txt"
ls "$OUT"/frames/*.png >/dev/null 2>&1 || fail "viewer wrote no frames"
echo "PASS"
