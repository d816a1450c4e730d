/* SPDX-License-Identifier: Apache-2.0 */
/* stone: a rigid spherical object inside an organ (docs/methods.md A: kidney-stone
 * removal with a laparoscope).
 *
 * The stone is static unless an extractor holds it; held, its centre
 * follows the tool tip at the offset it had when grabbed. It pushes the
 * organ's surface out of its way: every surface vertex inside the sphere
 * gets a penalty force k * depth along the outward radial direction,
 * clamped to STONE_MAX_VERTEX_FORCE per vertex, so a stone dragged out hard
 * enough slips through the tissue instead of tenting it without end (the
 * access incision is not modelled). The reaction goes to the holding tool.
 * Removal: the centre is outside the organ's rest surface (generalised
 * winding number < 1/2) by more than the radius.
 * Plain data, no allocation. */
#ifndef VISCERA_STONE_H
#define VISCERA_STONE_H

#include <stddef.h>
#include <stdint.h>

#define STONE_MAX_VERTEX_FORCE 0.05 /* N */
#define STONE_REST_STIFFNESS 300.0  /* N/m, penalty while nobody holds the stone */

typedef struct stone {
  double radius;    /* m */
  int organ;        /* organ it started in */
  double pos[3];    /* centre, m */
  int held_by;      /* tool index or -1 */
  double offset[3]; /* centre - tip at the grab */
  double force[3];  /* N, tissue reaction on the stone, last evaluation */
  int removed;      /* removal criterion met (latched) */
} stone_t;

void stone_init(stone_t *s, double radius, int organ, const double pos[3]);

/* Generalised winding number of the closed surface (x, tris) at p: 1
 * inside, 0 outside, 1/2 on the surface (solid angles summed, so a mesh
 * with small holes still gives a sensible answer). */
double stone_winding_number(const double *x, const uint32_t *tris, size_t ntris, const double p[3]);

/* Distance from p to the surface (x, tris), m (brute force; for checks
 * every few steps, not every sub-step). */
double stone_surface_distance(const double *x, const uint32_t *tris, size_t ntris, const double p[3]);

/* Penalty forces on the vertices of surface x (nsurf) inside the stone.
 * For each such vertex calls add(ctx, i, f); accumulates the reaction on
 * the stone in s->force (reset first). k in N/m. Returns how many vertices
 * it pushed. */
size_t stone_push(stone_t *s, const double *x, size_t nsurf, double k,
                  void (*add)(void *ctx, uint32_t i, const double f[3]), void *ctx);

/* Whether a tip at `tip` with jaws reaching `reach` (m beyond the stone's
 * surface) can take the stone. */
int stone_within_reach(const stone_t *s, const double tip[3], double reach);

void stone_grab(stone_t *s, int tool, const double tip[3]);
void stone_follow(stone_t *s, const double tip[3]);
void stone_release(stone_t *s);

/* The removal criterion against the organ's rest surface; latches
 * s->removed and returns it. */
int stone_check_removed(stone_t *s, const double *x_rest, const uint32_t *tris, size_t ntris);

#endif
