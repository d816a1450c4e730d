/* SPDX-License-Identifier: Apache-2.0 */
/* docs/numerics.md §5 case 5: a zero-length spring, and two vertices moved onto
 * each other: all forces (and the Jacobian products the implicit solver
 * uses) stay finite, and every integrator steps on without a rollback.
 *
 *  - a 4 x 4 patch whose vertices 5 and 6 coincide at rest (a spring of rest
 *    length 0, two zero-area triangles);
 *  - the octahedron with vertex 0 moved onto vertex 2 (a spring of length 0
 *    and rest length r sqrt 2);
 *  - a tetrahedral bar with one node moved onto a neighbour. */
#include "physics/mass_spring.h"
#include "stab_util.h"

static const char *const INTEGRATORS[] = {"explicit_euler", "symplectic_euler", "verlet", "rk4",
                                          "implicit_euler", "implicit_pcg"};

/* Forces and both Jacobian products finite at the current state. */
static int finite_everywhere(mass_spring_t *ms) {
  size_t n3 = 3 * ms->n;
  double *f = malloc(n3 * sizeof(double)), *y = malloc(n3 * sizeof(double)), *out = malloc(n3 * sizeof(double));
  for (size_t c = 0; c < n3; c++) y[c] = stab_rand();
  mass_spring_forces(ms, ms->x, ms->v, f);
  int ok = stab_finite(f, n3);
  for (int definite = 0; definite < 2; definite++) {
    ms->definite_jacobian = definite;
    mass_spring_stiffness_mul(ms, ms->x, 1, 0.5, y, out);
    ok = ok && stab_finite(out, n3);
  }
  ms->definite_jacobian = 0;
  ok = ok && isfinite(mass_spring_energy(ms)) && isfinite(mass_spring_max_strain(ms));
  free(f);
  free(y);
  free(out);
  return ok;
}

/* Each integrator from the state `setup` leaves: 200 steps of 1 ms, no
 * rollback, finite throughout. Returns how many integrators passed. */
static int step_all(const mesh_t *mesh, const char *model, void (*setup)(model_t *)) {
  int passed = 0;
  for (size_t k = 0; k < sizeof INTEGRATORS / sizeof INTEGRATORS[0]; k++) {
    char extra[400];
    snprintf(extra, sizeof extra,
             "    model: %s\n    integrator: %s\n    solver: {tet_size: 0.005}\n"
             "    material: {mass: 0.05, stiffness: 100, damping: 0.05, home_stiffness: 10, home_damping: 0.01}\n",
             model, INTEGRATORS[k]);
    scene_organ_t c = stab_organ(extra);
    verr_t err;
    model_t *m = stab_model(&c, mesh, NULL, 1e-3, &err);
    if (!m) {
      fprintf(stderr, "  %s/%s: %s\n", model, INTEGRATORS[k], err.msg);
      continue;
    }
    setup(m);
    int ok = 1;
    for (int s = 0; s < 200; s++) ok = ok && m->ops->step(m, 1e-3) == 0;
    ok = ok && m->rollbacks == 0 && stab_finite(m->x, 3 * m->nnodes) && stab_finite(m->v, 3 * m->nnodes) &&
         stab_finite(m->surf_x, 3 * m->nsurf) && isfinite(m->ops->energy(m)) && isfinite(m->ops->error_estimate(m));
    if (!ok) fprintf(stderr, "  %s/%s: rollback or non-finite state\n", model, INTEGRATORS[k]);
    passed += ok;
    model_destroy(m);
  }
  return passed;
}

static void nothing(model_t *m) { (void)m; }
static void onto_neighbour(model_t *m) { v3_copy(m->x, m->x + 6); } /* octahedron: 0 onto 2 */
static uint32_t g_node_a, g_node_b;
static void tet_onto_neighbour(model_t *m) { v3_copy(m->x + 3 * g_node_a, m->x + 3 * g_node_b); }

int main(void) {
  verr_t err;
  ms_params_t p = {.mass = 0.05,
                   .stiffness = 100,
                   .damping = 0.05,
                   .home_stiffness = 10,
                   .home_damping = 0.01,
                   .gravity = {0, 0, -9.81}};
  mass_spring_t ms;

  /* Zero rest length: vertices 5 and 6 of a 4 x 4 patch at one point. */
  mesh_t patch;
  stab_grid(&patch, 4, 0.01);
  v3_copy(patch.pos + 3 * 6, patch.pos + 3 * 5);
  CHECK(mass_spring_create_surface(&ms, &patch, &p, &err) == 0);
  int zero_rest = 0;
  for (size_t s = 0; s < ms.nsprings; s++) zero_rest += ms.springs[s].rest == 0;
  CHECK(zero_rest == 1);
  CHECK(finite_everywhere(&ms));
  for (size_t c = 0; c < 3 * ms.n; c++) ms.x[c] += 1e-3 * stab_rand();
  CHECK(finite_everywhere(&ms));
  double lk, lc;
  CHECK(mass_spring_eigen_bounds(&ms, 0, &lk, &lc) == 0 && isfinite(lk) && isfinite(lc) && lk > 0);
  mass_spring_destroy(&ms);
  CHECK(step_all(&patch, "mass_spring_surface", nothing) == (int)(sizeof INTEGRATORS / sizeof INTEGRATORS[0]));
  mesh_free(&patch);

  /* Two vertices moved onto each other (octahedron 0 onto 2). */
  mesh_t oct;
  stab_octahedron(&oct, 0.05);
  CHECK(mass_spring_create_surface(&ms, &oct, &p, &err) == 0);
  v3_copy(ms.x, ms.x + 6);
  CHECK(finite_everywhere(&ms));
  for (size_t c = 0; c < 18; c++) ms.v[c] = stab_rand();
  CHECK(finite_everywhere(&ms));
  mass_spring_destroy(&ms);
  CHECK(step_all(&oct, "mass_spring_surface", onto_neighbour) == (int)(sizeof INTEGRATORS / sizeof INTEGRATORS[0]));

  /* The same in a tetrahedral mesh: a node onto a neighbour. */
  mesh_t box;
  stab_box(&box, 2, 2, 4, 0.02, 0.02, 0.04);
  tet_mesh_t t;
  tet_embedding_t emb;
  CHECK(tet_mesh_build(&box, 0.005, &t, &emb, NULL, &err) == 0);
  CHECK(mass_spring_create_tets(&ms, &t, &p, &err) == 0);
  g_node_a = ms.springs[ms.nsprings / 2].i;
  g_node_b = ms.springs[ms.nsprings / 2].j;
  v3_copy(ms.x + 3 * g_node_a, ms.x + 3 * g_node_b);
  CHECK(finite_everywhere(&ms));
  mass_spring_destroy(&ms);
  tet_mesh_free(&t);
  tet_embedding_free(&emb);
  /* The model builds the same tetrahedra (same surface, same size), so the
   * node pair is the same. */
  CHECK(step_all(&box, "mass_spring_tet", tet_onto_neighbour) == (int)(sizeof INTEGRATORS / sizeof INTEGRATORS[0]));
  mesh_free(&box);
  mesh_free(&oct);
  printf("zero-length springs: forces, Jacobians and 5 integrators x 3 meshes finite\n");
  return check_report("stab_degenerate");
}
