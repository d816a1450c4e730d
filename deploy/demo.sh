#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The main job: installs what is missing, builds, and runs a complete local
# session on loopback (server, scripted haptic client pushing into the kidney
# and releasing, offscreen viewer writing PNG frames, recorder writing one
# SQLite file), then prints where everything is and a one-line summary.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$ROOT/deploy/install_deps.sh"
echo "demo: building (build/)"
bash "$ROOT/deploy/build.sh" "$ROOT/build" -DVISCERA_BUILD_TESTS=OFF
OUT="$ROOT/out/session-$(date +%Y%m%d-%H%M%S)"
bash "$ROOT/deploy/session.sh" "$ROOT/build" "$OUT" "$@"

val() { grep -ho "$1=[^ ]*" "$2" 2>/dev/null | tail -1 | cut -d= -f2; }
peak=$(val peak_force "$OUT/haptic.out")
frames=$(val frames "$OUT/viewer.out")
samples=$(val samples "$OUT/recorder.out")
lat=$(val latency_us_median "$OUT/haptic.out")
echo
echo "frames:    $OUT/frames/ (index: frames.csv)"
echo "recording: $OUT/session.db (inspect: build/client/recorder/viscera-recinfo $OUT/session.db)"
echo "logs:      $OUT/*.log"
# The trainee report of this session (HTML with charts, CSV).
if [ -x "$ROOT/build/client/report/viscera-report" ] &&
  "$ROOT/build/client/report/viscera-report" --quiet --out "$OUT/report" --label "trainee=$OUT/session.db"; then
  echo "report:    $OUT/report/report.html (CSV: report.csv)"
fi
echo "summary:   peak contact force ${peak:-?} N, ${frames:-?} frames rendered, ${samples:-?} samples recorded, command->feedback latency median ${lat:-?} us"
