# Pixel checks of the dashboard's focus view, sourced by the dashboard_focus
# and dashboard_window tests. The places follow client/dashboard/dash_draw.c:
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
