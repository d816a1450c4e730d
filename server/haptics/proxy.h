/* SPDX-License-Identifier: Apache-2.0 */
/* proxy: god-object haptic proxy with a virtual spring (docs/methods.md A eq. 12).
 *
 * The device point (SUN) may sink into an organ; the proxy (IUN) may not: it
 * stays on the deforming surface, attached to a triangle by barycentric
 * coordinates so it moves with the tissue. The tool feels f = K (proxy - device),
 * clamped to max_force; the tissue feels -f at the contact triangle.
 * Contact starts when the device path crosses a triangle from outside (so a
 * tool pushed 10 cm inside keeps its proxy on the entry surface) and ends when
 * the device is more than PROXY_RELEASE_MARGIN above the tangent plane at the
 * proxy (within it the tool touches with zero force). The proxy slides
 * frictionlessly: each tick it moves to the surface point nearest the device
 * projected onto the current tangent plane.
 * The contact normal is the contact triangle's rest normal when rest
 * positions are given: the dented surface's own triangles tilt wildly under
 * a probe, while the organ's undeformed orientation is what the hand pushes
 * against. The tool tip is a point. Queries scan every triangle, or use the
 * surface's AABB tree when one is given (same results, see below). */
#ifndef VISCERA_PROXY_H
#define VISCERA_PROXY_H

#include <stddef.h>
#include <stdint.h>

/* m: the device must rise this far above the tangent plane to release. */
#define PROXY_RELEASE_MARGIN 1e-3

typedef struct proxy_surface {
  const double *x;       /* 3 per vertex, current positions */
  const uint32_t *tris;  /* 3 per triangle, outward CCW */
  size_t ntris;
  double max_edge;       /* m, bound on any edge length while deformed (0: no culling) */
  const double *x_rest;  /* rest positions for contact normals, or NULL for current */
  /* Optional AABB tree over (x, tris) (collision/aabb_tree.h), or NULL to scan
   * every triangle. It must be refit from x after every change of x (each
   * physics step) before the next proxy_update; with it the proxy gives the
   * same results as the scan. It is used only while it was last refit from
   * this very x array and has ntris triangles; otherwise the scan runs. */
  const struct aabb_tree *tree;
  /* Force shading: unit vertex normals (3 per vertex, of x_rest if given,
   * see proxy_vertex_normals) or NULL. With them the contact normal is the
   * normal interpolated with the proxy's barycentric coordinates, so it
   * turns smoothly across edges and the hand does not feel the facets.
   * nvn: vertices in vn; a triangle indexing beyond it (the surface changed
   * topology and vn was not rebuilt) gets its face normal. */
  const double *vn;
  size_t nvn;
} proxy_surface_t;

typedef struct proxy {
  int in_contact;
  int surface;       /* index into the surfaces array while in contact, else -1 */
  uint32_t tri;      /* contact triangle */
  double bary[3];    /* proxy in that triangle */
  double pos[3];     /* proxy position (device position when free) */
  double normal[3];  /* outward unit normal at the proxy (valid in contact) */
  double device_prev[3];
  int have_prev;
  /* Settling offset (m), zero except after a topology change under the
   * proxy (runtime/topology_follow.h): the proxy keeps its place in space
   * although the surface point it re-attached to differs (a simplified mesh
   * cannot hold the refined dent), and the offset decays with time constant
   * PROXY_SETTLE_TAU (proxy_settle), so the force ramps instead of jumping. */
  double settle[3];
} proxy_t;

/* s: time constant of the settling offset. The force then changes by at
 * most K |offset| dt / tau per step (1.25 mm at 400 N/m: 10 mN per 1 ms). */
#define PROXY_SETTLE_TAU 0.05

void proxy_reset(proxy_t *p);

/* One haptic tick. `device` is the commanded tool tip; writes the force on the
 * tool into force[3] (zero when free) and returns 1 if in contact. */
int proxy_update(proxy_t *p, const double device[3], const proxy_surface_t *surfaces, size_t nsurfaces,
                 double stiffness, double max_force, double force[3]);

/* The virtual spring f = K (proxy - device) (docs/methods.md A eq. 12: f = -K x with
 * x = device - proxy), clamped to max_force; zero when not in contact.
 * Returns |f|. */
double proxy_spring_force(const proxy_t *p, const double device[3], double stiffness, double max_force, double f[3]);

/* The same tick with Coulomb friction mu >= 0 on the proxy's motion: the
 * proxy sticks while the tangential spring force K |tangential offset|
 * stays within the cone mu * normal force, and beyond it slides only as
 * far as keeps the offset on the cone (static = dynamic coefficient).
 * mu = 0 is proxy_update. */
int proxy_update_friction(proxy_t *p, const double device[3], const proxy_surface_t *surfaces, size_t nsurfaces,
                          double stiffness, double max_force, double mu, double force[3]);

/* Area-weighted unit vertex normals of (x, tris) into vn (3 per vertex;
 * zero for a vertex in no triangle), for proxy_surface_t.vn. */
void proxy_vertex_normals(size_t nverts, const double *x, size_t ntris, const uint32_t *tris, double *vn);

/* Re-evaluates pos and normal from the attached triangle's current vertices
 * (call after the surface moved, e.g. after a physics step); pos includes
 * the settling offset. */
void proxy_follow_surface(proxy_t *p, const proxy_surface_t *surfaces, size_t nsurfaces);

/* Decays the settling offset by exp(-dt / PROXY_SETTLE_TAU) (once per
 * physics step); below 1 nm it is zeroed. No-op when it is zero. */
void proxy_settle(proxy_t *p, double dt);

#endif
