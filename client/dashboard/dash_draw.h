/* SPDX-License-Identifier: Apache-2.0 */
/* dash_draw: the dashboard's two pictures, drawn with cairo over the seats'
 * state (seat.h), for the PNG frames and the window alike.
 *
 * - The grid: one tile per seat (cols per row): a header (partition, scene,
 *   force), the organ as the viewer draws it (one OSMesa renderer at tile
 *   size for every tile), the force over the last DASH_GRAPH_SECONDS against
 *   the thresholds, and an alert frame in the level's colour while an alert
 *   holds (seat.h SEAT_ALERT_HOLD_S).
 * - The focus view of one seat, at any size from DASH_FOCUS_MIN_W x
 *   DASH_FOCUS_MIN_H: the scene large, the current level as a coloured
 *   badge, force now and peak, time above each threshold, the thresholds,
 *   who drives the primary tool and who guides it (ToolRole), the last seat
 *   events, and the force graph with axes in N and seconds.
 *
 * Colours mean the same everywhere (seat_text.h seat_level_rgb). Drawing
 * never fails for a seat without a server or scene: it says so instead.
 * Not thread-safe (one OSMesa context per renderer, used from the caller's
 * thread). */
#ifndef VISCERA_DASHBOARD_DASH_DRAW_H
#define VISCERA_DASHBOARD_DASH_DRAW_H

#include <cairo.h>

#include "view/render.h"
#include "seat.h"

#define DASH_HEADER_H 22 /* tile header, px */
#define DASH_GRAPH_H 70  /* tile force graph, px */
#define DASH_GRAPH_SECONDS 30.0
#define DASH_SAMPLE_HZ 10.0 /* force history rate (seat_sample calls per s) */
#define DASH_FOCUS_MIN_W 640
#define DASH_FOCUS_MIN_H 420
#define DASH_FOCUS_HEADER_H 48 /* the focus view's title band; the level badge sits in it */
#define DASH_FOCUS_MARGIN 14

typedef struct dash {
  seat_t *seats;
  int nseats, cols, rows;
  int tw, th; /* tile scene size, px */
  render_t *r_tile;
  render_t *r_focus; /* the focus view's scene, reopened when its size changes */
  int fw, fh;
} dash_t;

/* Sets up the grid (cols > 0) and opens the tile renderer. 0, or -1 with err. */
int dash_open(dash_t *d, seat_t *seats, int nseats, int cols, int tw, int th, verr_t *err);
void dash_close(dash_t *d);

/* The grid's size in pixels. */
void dash_grid_size(const dash_t *d, int *w, int *h);
/* Frames a seat's tile camera once its scene is complete (call after polling). */
void dash_update(dash_t *d);
/* Draws the grid with its top-left corner at (x0, y0) of cr's image surface. */
void dash_draw_grid(dash_t *d, cairo_t *cr, int x0, int y0, verr_t *err);
/* The seat whose tile covers (x, y) in a grid drawn at (x0, y0), or -1. */
int dash_tile_at(const dash_t *d, int x0, int y0, int x, int y);
/* Draws seat i's focus view over the whole w x h image surface of cr
 * (w >= DASH_FOCUS_MIN_W, h >= DASH_FOCUS_MIN_H). Returns 0, or -1 with err
 * when the scene renderer cannot be (re)opened; the rest is drawn anyway. */
int dash_draw_focus(dash_t *d, int i, cairo_t *cr, int w, int h, verr_t *err);

/* The badge's rectangle in a w x h focus view (tests look for its colour). */
void dash_focus_badge_rect(int w, int h, int *x, int *y, int *bw, int *bh);

#endif
