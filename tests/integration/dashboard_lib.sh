# SPDX-License-Identifier: Apache-2.0
# Shared by the dashboard_focus and dashboard_window tests (sourced once
# BUILD and OUT are set): process clean-up, fail(), a fresh $OUT, the
# trainee's trajectory, and pixel checks of the dashboard's focus view.
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log "$OUT"/*.out; do echo "--- $f"; tail -8 "$f"; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"

# write_hold_traj FILE END: press 8 mm into the default kidney (about 0.97 N:
# above MPF 0.8, below SFT 1.5) from 1.5 s, hold until END s, withdraw.
write_hold_traj() {
  printf '%s\n' "0.0 0.012 0.004 0.070" "0.5 0.012 0.004 0.070" "1.5 0.012 0.004 0.027" \
    "$2 0.012 0.004 0.027" "$(($2 + 1)) 0.012 0.004 0.070" "$(($2 + 2)) 0.012 0.004 0.070" > "$1"
}

# Pixel checks. The places follow client/dashboard/dash_draw.c:
# the level badge is 230x34 px at (W - 14 - 230, 7); the force graph fills
# the bottom 30 % of the view; an alert frames the view (6 px); colours are
# seat_text.c's.
# needs: $BUILD (png_region is built in tests/integration)

# Pixels of colour R G B (tolerance TOL) in the rectangle X Y W H of FILE.
px_count() {
  "$BUILD/tests/integration/png_region" "$@" | sed -n 's/^match=\([0-9]*\) of .*/\1/p'
}
# focus_badge_is FILE W R G B: most of the badge has that colour.
focus_badge_is() {
  local n; n=$(px_count "$1" $(($2 - 14 - 230)) 7 230 34 "$3" "$4" "$5" 8)
  [ "${n:-0}" -ge 5000 ]
}
# focus_has_curve FILE W H: the force curve (light blue) is drawn in the graph.
focus_has_curve() {
  local n; n=$(px_count "$1" 0 $(($3 * 6 / 10)) "$2" $(($3 * 4 / 10)) 140 217 255 10)
  [ "${n:-0}" -ge 150 ]
}
# focus_framed FILE H R G B: the alert frame (6 px at the border) has that colour.
focus_framed() {
  local n; n=$(px_count "$1" 0 60 6 $(($2 - 120)) "$3" "$4" "$5" 8)
  [ "${n:-0}" -ge $((($2 - 120) * 6 / 2)) ]
}
BADGE_MPF=(230 51 51)    # above MPF: red
BADGE_NONE=(89 89 102)   # no contact: grey

# scan_focus_frames DIR W H: sets red (focus frames with the above-MPF
# badge), and among those curve (force curve drawn) and framed (red frame).
scan_focus_frames() {
  red=0; curve=0; framed=0
  for f in "$1"/focus_*.png; do
    if focus_badge_is "$f" "$2" "${BADGE_MPF[@]}"; then
      red=$((red + 1))
      focus_has_curve "$f" "$2" "$3" && curve=$((curve + 1))
      focus_framed "$f" "$3" "${BADGE_MPF[@]}" && framed=$((framed + 1))
    fi
  done
}
