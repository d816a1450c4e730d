/* SPDX-License-Identifier: Apache-2.0 */
/* grasp: a grasper holding a small patch of tissue (docs/methods.md A: hold, pull).
 *
 * When the jaws close with the tip within the grasp radius of a surface,
 * grasp_take() takes the surface vertices within that radius of the tip (at
 * most GRASP_MAX_VERTS, the nearest), each with a weight (1 - d/r)^2
 * normalised to sum 1, and remembers each vertex's offset from the tip.
 * While held, grasp_force() pulls vertex i towards tip + offset_i with a
 * spring k w_i (k = the tool's stiffness, so the organ's sub-step bound,
 * which already includes the stiffest tool, keeps it stable); the sum is
 * clamped to the tool's max force and the tool feels the opposite. Moving
 * the tool pulls or pushes the tissue; grasp_release() lets go.
 * Plain data, no allocation; the runtime calls it every sub-step. */
#ifndef VISCERA_GRASP_H
#define VISCERA_GRASP_H

#include <stddef.h>
#include <stdint.h>

#define GRASP_MAX_VERTS 16

typedef struct grasp {
  int active;
  int organ;                         /* organ index while active, else -1 */
  size_t n;                          /* vertices held */
  uint32_t v[GRASP_MAX_VERTS];       /* surface vertex indices */
  double w[GRASP_MAX_VERTS];         /* weights, sum 1 */
  double offset[GRASP_MAX_VERTS][3]; /* vertex - tip at the grasp, m */
  double anchor[3];                  /* tip at the grasp, m */
} grasp_t;

void grasp_init(grasp_t *g);

/* Tries to grasp the surface x (nsurf vertices) of organ `organ` with the
 * tip at `tip` and jaws reaching `radius`. Returns the number of vertices
 * taken (0: nothing within reach, g stays released). */
size_t grasp_take(grasp_t *g, int organ, const double *x, size_t nsurf, const double tip[3], double radius);

/* Forces while held: writes the force on each held vertex (3 per vertex,
 * in the order of g->v) into fv and the force on the tool into f_tool;
 * returns |f_tool|. Zero when not active. */
double grasp_force(const grasp_t *g, const double *x, const double tip[3], double k, double max_force, double fv[][3],
                   double f_tool[3]);

/* Weighted mean position of the held vertices, m. */
void grasp_patch_centre(const grasp_t *g, const double *x, double c[3]);

void grasp_release(grasp_t *g);

#endif
