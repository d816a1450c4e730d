#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Issue 14.2: ToolCommands arriving newer-first in pairs (as over a
# reordering link) are applied newest-wins: the server skips each older one
# and counts it (flood_commands reorder / reorder-check).
# usage: command_order_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
PART=hardnet/order PAIRS=500
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $PART --duration 60 \
  > "$OUT/server.out" 2> "$OUT/server.log" & SRV=$!; PIDS+=($SRV)
"$BUILD/tests/integration/flood_commands" reorder "$VISCERA_DOMAIN" $PART $PAIRS 2> "$OUT/reorder.log" \
  || fail "reorder publisher"
kill -INT $SRV; wait $SRV || fail "server exit status"
"$BUILD/tests/integration/flood_commands" reorder-check "$OUT/server.out" $PAIRS || fail "check"
echo PASS
