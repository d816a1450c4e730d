/* SPDX-License-Identifier: Apache-2.0 */
/* test_tet_cut: progressive tetrahedral cutting (server/cutting/tet_cut.h).
 *
 * Every split case on one hand-made tetrahedron (G1, G2, P1, P2, P3): rest
 * volume conserved to 1e-12, no gaps (every face shared by at most two
 * tetrahedra), the boundary closed and manifold (every directed boundary
 * edge matched by its reverse exactly once), and the number of pieces (two
 * for a general case on a lone tetrahedron, one for a partial case). A cut
 * through a box grid in several blade steps gives two pieces; cuts through
 * grid nodes and along grid faces (the degenerate intersections) never give
 * flat, inverted or non-finite elements. The seed's rest-length rules agree
 * with measuring the interpolated rest configuration. The PBD model with
 * cutting: a scene model allocates no cutter until a cut starts; 1 s after
 * cutting a bar fixed at both ends, everything is finite and the two halves
 * hang apart (the middle sags far more than the uncut bar's). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cutting/tet_cut.h"
#include "cutting/tet_model_cut.h"
#include "cutting/tet_split.h"
#include "mesh.h"
#include "physics/pbd.h"
#include "scene.h"
#include "tet_mesh.h"
#include "vmath.h"

static double rest_volume(const tet_cut_t *c) {
  double v = 0;
  for (size_t t = 0; t < c->ntets; t++) {
    const uint32_t *q = c->tet + 4 * t;
    double g[4][3];
    v += pbd_volume_constraint(c->x_rest + 3 * (size_t)q[0], c->x_rest + 3 * (size_t)q[1], c->x_rest + 3 * (size_t)q[2],
                               c->x_rest + 3 * (size_t)q[3], 0, g) /
         6.0;
  }
  return v;
}

static int cmp_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

/* Faces shared by more than two tetrahedra (0 for a conforming mesh). */
static size_t overshared_faces(const tet_cut_t *c) {
  uint64_t *k = malloc(4 * c->ntets * sizeof *k);
  for (size_t t = 0; t < c->ntets; t++)
    for (int f = 0; f < 4; f++) {
      uint64_t a[3];
      int m = 0;
      for (int j = 0; j < 4; j++)
        if (j != f) a[m++] = c->tet[4 * t + j];
      for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
          if (a[j] < a[i]) {
            uint64_t s = a[i];
            a[i] = a[j];
            a[j] = s;
          }
      k[4 * t + f] = a[0] << 42 | a[1] << 21 | a[2];
    }
  qsort(k, 4 * c->ntets, sizeof *k, cmp_u64);
  size_t bad = 0;
  for (size_t i = 2; i < 4 * c->ntets; i++)
    if (k[i] == k[i - 2]) bad++;
  free(k);
  return bad;
}

/* Directed boundary edges: closed and manifold iff each (a, b) appears once
 * and its reverse (b, a) once. Returns the number of violations. */
static size_t boundary_defects(const tet_cut_t *c, size_t *nfaces) {
  uint32_t *tris;
  size_t nf = tet_cut_boundary(c, &tris);
  *nfaces = nf;
  uint64_t *e = malloc(3 * nf * sizeof *e);
  for (size_t f = 0; f < nf; f++)
    for (int k = 0; k < 3; k++) e[3 * f + k] = (uint64_t)tris[3 * f + k] << 32 | tris[3 * f + (k + 1) % 3];
  qsort(e, 3 * nf, sizeof *e, cmp_u64);
  size_t bad = 0;
  for (size_t i = 0; i < 3 * nf; i++) {
    if (i > 0 && e[i] == e[i - 1]) bad++;
    uint64_t rev = (e[i] & 0xffffffffu) << 32 | e[i] >> 32;
    if (!bsearch(&rev, e, 3 * nf, sizeof *e, cmp_u64)) bad++;
  }
  free(e);
  free(tris);
  return bad;
}

/* Pieces: tetrahedra sharing a node are connected. */
static size_t pieces(const tet_cut_t *c) {
  uint32_t *par = malloc(c->n * sizeof *par);
  for (size_t i = 0; i < c->n; i++) par[i] = (uint32_t)i;
  for (size_t t = 0; t < c->ntets; t++)
    for (int k = 1; k < 4; k++) {
      uint32_t a = c->tet[4 * t], b = c->tet[4 * t + k];
      while (par[a] != a) a = par[a];
      while (par[b] != b) b = par[b];
      par[a] = b;
    }
  uint8_t *used = calloc(c->n, 1);
  for (size_t k = 0; k < 4 * c->ntets; k++) used[c->tet[k]] = 1;
  size_t count = 0;
  for (size_t i = 0; i < c->n; i++)
    if (used[i] && par[i] == i) count++;
  free(par);
  free(used);
  return count;
}

static double min_quality(const tet_cut_t *c, const double *x) {
  double q = INFINITY;
  for (size_t t = 0; t < c->ntets; t++) q = fmin(q, tet_cut_quality(c, x, t));
  return q;
}

static int all_finite(const tet_cut_t *c) {
  for (size_t k = 0; k < 3 * c->n; k++)
    if (!isfinite(c->x[k]) || !isfinite(c->x_rest[k]) || !isfinite(c->v[k])) return 0;
  for (size_t k = 0; k < 2 * c->n; k++)
    if (!isfinite(c->attr[k])) return 0;
  return 1;
}

/* The checks every cut result must pass. */
static void check_mesh(const tet_cut_t *c, double v0, const char *what) {
  size_t nf;
  double v = rest_volume(c);
  size_t over = overshared_faces(c), defects = boundary_defects(c, &nf);
  double q = min_quality(c, c->x_rest);
  printf("  %-28s %4zu nodes %5zu tets %5zu boundary faces, min quality %.3f, volume err %.1e, %zu pieces\n", what,
         c->n, c->ntets, nf, q, fabs(v / v0 - 1), pieces(c));
  CHECK(fabs(v / v0 - 1) <= 1e-12);
  CHECK(over == 0);
  CHECK(defects == 0);
  CHECK(q > 0.01);
  CHECK(all_finite(c));
}

/* A blade sweep as a list of (tip, handle) positions, then the end. */
static void run_blade(tet_cut_t *c, const double (*tip)[3], const double (*handle)[3], int steps) {
  verr_t err;
  for (int s = 0; s < steps; s++) CHECK(tet_cut_advance(c, tip[s], handle[s], &err) >= 0);
  CHECK(tet_cut_end(c, &err) >= 0);
}

static const double TET_X[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const uint32_t TET_Q[4] = {0, 1, 2, 3};

static void one_tet(tet_cut_t *c) {
  verr_t err;
  CHECK(tet_cut_create(c, 4, TET_X, NULL, NULL, NULL, 1, TET_Q, &err) == 0);
}

static void test_classify(void) {
  int side[4];
  CHECK(tet_split_classify(0, NULL) == TET_SPLIT_NONE);
  CHECK(tet_split_classify(1u << 0 | 1u << 1 | 1u << 2, side) == TET_SPLIT_G1); /* node 0 alone */
  CHECK(side[0] != side[1] && side[1] == side[2] && side[2] == side[3]);
  CHECK(tet_split_classify(1u << 2 | 1u << 4 | 1u << 5, side) == TET_SPLIT_G1);           /* node 3 alone */
  CHECK(tet_split_classify(1u << 1 | 1u << 2 | 1u << 3 | 1u << 4, side) == TET_SPLIT_G2); /* 01 | 23 */
  CHECK(side[0] == side[1] && side[2] == side[3] && side[0] != side[2]);
  CHECK(tet_split_classify(1u << 0, NULL) == TET_SPLIT_P1);
  CHECK(tet_split_classify(1u << 0 | 1u << 5, NULL) == TET_SPLIT_P2);
  CHECK(tet_split_classify(1u << 0 | 1u << 1 | 1u << 5, NULL) == TET_SPLIT_P3); /* a path: seed fig. 9, state 3 */
  CHECK(tet_split_classify(1u << 0 | 1u << 1 | 1u << 3, NULL) == TET_SPLIT_P3); /* a face's three edges */
  CHECK(tet_split_classify(63u, NULL) == TET_SPLIT_P3);
}

static void test_general_cases(void) {
  tet_cut_t c;
  double v0 = 1.0 / 6;
  /* G1: the plane z = 0.4 cuts node 3 off; the blade (along x) sweeps y. */
  one_tet(&c);
  {
    double tip[3][3] = {{-1, -1, 0.4}, {-1, 0.5, 0.4}, {-1, 2, 0.4}};
    double han[3][3] = {{2, -1, 0.4}, {2, 0.5, 0.4}, {2, 2, 0.4}};
    run_blade(&c, (const double(*)[3])tip, (const double(*)[3])han, 3);
  }
  CHECK(c.stats.split_general[0] == 1 && c.ntets == 4);
  CHECK(pieces(&c) == 2);
  CHECK(c.stats.duplicated == 3);
  check_mesh(&c, v0, "G1 (1|3)");
  tet_cut_destroy(&c);
  /* G2: the plane x + y = 0.5 separates {0, 3} from {1, 2}; the blade
   * (along z) moves along the plane. */
  one_tet(&c);
  {
    double tip[3][3] = {{1.5, -1, -1}, {0.5, 0, -1}, {-0.5, 1, -1}};
    double han[3][3] = {{1.5, -1, 2}, {0.5, 0, 2}, {-0.5, 1, 2}};
    run_blade(&c, (const double(*)[3])tip, (const double(*)[3])han, 3);
  }
  CHECK(c.stats.split_general[1] == 1 && c.ntets == 6);
  CHECK(pieces(&c) == 2);
  CHECK(c.stats.duplicated == 4);
  check_mesh(&c, v0, "G2 (2|2)");
  tet_cut_destroy(&c);
  /* Through two nodes: the plane x = y holds nodes 0 and 3 and crosses edge
   * 12. Nodes on the plane count as on its positive side, so node 2 (x < y)
   * is cut off alone (G1) and the points on its edges to nodes 0 and 3 sit
   * a quarter edge from them (the snap), never on them. */
  one_tet(&c);
  {
    double tip[2][3] = {{-1, -1, -1}, {2, 2, -1}};
    double han[2][3] = {{-1, -1, 2}, {2, 2, 2}};
    run_blade(&c, (const double(*)[3])tip, (const double(*)[3])han, 2);
  }
  CHECK(c.stats.split_general[0] == 1 && pieces(&c) == 2);
  for (size_t i = 4; i < c.n; i++)
    for (size_t j = 0; j < 4; j++) CHECK(v3_dist(c.x_rest + 3 * i, TET_X + 3 * j) > 0.2);
  check_mesh(&c, v0, "G1 through two nodes");
  tet_cut_destroy(&c);
}

static void test_partial_cases(void) {
  tet_cut_t c;
  double v0 = 1.0 / 6;
  /* P1: the blade tip only reaches edge 01 (plane x = 0.5, z <= 0.05). */
  one_tet(&c);
  {
    double tip[2][3] = {{0.5, -0.3, 0.05}, {0.5, 0.05, 0.05}};
    double han[2][3] = {{0.5, -0.3, -0.5}, {0.5, 0.05, -0.5}};
    run_blade(&c, (const double(*)[3])tip, (const double(*)[3])han, 2);
  }
  CHECK(c.stats.split_partial[0] == 1 && c.ntets == 2 && pieces(&c) == 1 && c.stats.duplicated == 0);
  check_mesh(&c, v0, "P1 (one edge)");
  tet_cut_destroy(&c);
  /* P2: plane x + y = 0.5 below z = 0.1: edges 01 and 02. */
  one_tet(&c);
  {
    double tip[2][3] = {{1.5, -1, 0.1}, {-0.5, 1, 0.1}};
    double han[2][3] = {{1.5, -1, -0.5}, {-0.5, 1, -0.5}};
    run_blade(&c, (const double(*)[3])tip, (const double(*)[3])han, 2);
  }
  CHECK(c.stats.split_partial[1] == 1 && c.ntets == 3 && pieces(&c) == 1);
  check_mesh(&c, v0, "P2 (two edges)");
  tet_cut_destroy(&c);
  /* P3 (the seed's state 3, a path of three edges 01, 02, 23): a fan in
   * the plane x + y = 0.5 around a fixed handle, which reaches the points
   * of 01, 02 and 23 but not that of 13. In-plane coordinates: u = x - y,
   * z; x = 0.25 + u / 2, y = 0.25 - u / 2. */
  one_tet(&c);
  {
#define P(u, z)                                                                                                        \
  { 0.25 + 0.5 * (u), 0.25 - 0.5 * (u), (z) }
    double tip[2][3] = {P(-1, 0.8), P(1, -0.2)};
    double han[2][3] = {P(-1, -0.5), P(-1, -0.5)};
#undef P
    run_blade(&c, (const double(*)[3])tip, (const double(*)[3])han, 2);
  }
  CHECK(c.stats.split_partial[2] == 1 && c.ntets == 5 && pieces(&c) == 1);
  check_mesh(&c, v0, "P3 (path of three edges)");
  tet_cut_destroy(&c);
}

/* A 6 x 3 x 3 node box (0.5 x 0.2 x 0.2 m), cut by a vertical blade along
 * z at x = xc, swept across y in `steps` advances. */
static void cut_box(tet_cut_t *c, double xc, double yz_tilt, int steps) {
  tet_mesh_t tm;
  verr_t err;
  CHECK(tet_mesh_box_grid(6, 3, 3, 0.1, &tm, &err) == 0);
  CHECK(tet_cut_create(c, tm.nnodes, tm.x, NULL, NULL, NULL, tm.ntets, tm.tets, &err) == 0);
  tet_mesh_free(&tm);
  for (int s = 0; s <= steps; s++) {
    double y = -0.1 + 0.4 * s / steps;
    double tip[3] = {xc + yz_tilt * y, y, -0.1}, han[3] = {xc + yz_tilt * y, y, 0.3};
    CHECK(tet_cut_advance(c, tip, han, &err) >= 0);
  }
  CHECK(tet_cut_end(c, &err) >= 0);
}

static void test_box(void) {
  tet_cut_t c;
  double v0 = 0.5 * 0.2 * 0.2;
  cut_box(&c, 0.27, 0, 5);
  CHECK(pieces(&c) == 2);
  CHECK(c.stats.split_general[0] + c.stats.split_general[1] > 0);
  check_mesh(&c, v0, "box, plane x = 0.27");
  tet_cut_destroy(&c);
  /* Through a plane of grid nodes and along grid faces. */
  cut_box(&c, 0.2, 0, 4);
  CHECK(pieces(&c) == 2);
  check_mesh(&c, v0, "box, grid plane x = 0.2");
  tet_cut_destroy(&c);
  /* Diagonal through grid nodes (x = 0.2 + y passes nodes and edges). */
  cut_box(&c, 0.2, 1.0, 4);
  check_mesh(&c, v0, "box, diagonal x = 0.2 + y");
  tet_cut_destroy(&c);
  /* A blade that stops halfway (tip inside): one piece, partial cases. */
  {
    tet_mesh_t tm;
    verr_t err;
    CHECK(tet_mesh_box_grid(6, 3, 3, 0.1, &tm, &err) == 0);
    CHECK(tet_cut_create(&c, tm.nnodes, tm.x, NULL, NULL, NULL, tm.ntets, tm.tets, &err) == 0);
    tet_mesh_free(&tm);
    for (int s = 0; s <= 4; s++) {
      double y = -0.1 + 0.2 * s / 4; /* up to y = 0.1, the middle */
      double tip[3] = {0.27, y, -0.1}, han[3] = {0.27, y, 0.3};
      CHECK(tet_cut_advance(&c, tip, han, &err) >= 0);
    }
    CHECK(tet_cut_end(&c, &err) >= 0);
    CHECK(pieces(&c) == 1);
    CHECK(c.stats.split_partial[0] + c.stats.split_partial[1] + c.stats.split_partial[2] > 0);
    CHECK(c.stats.duplicated > 0); /* the part behind the crack front opened */
    check_mesh(&c, v0, "box, blade stops halfway");
    tet_cut_destroy(&c);
  }
  /* A blade that does not move cuts nothing; a non-finite blade is refused. */
  {
    verr_t err;
    one_tet(&c);
    double tip[3] = {0.2, 0.2, -1}, han[3] = {0.2, 0.2, 2}, bad[3] = {NAN, 0, 0};
    CHECK(tet_cut_advance(&c, tip, han, &err) == 0);
    CHECK(tet_cut_advance(&c, tip, han, &err) == 0);
    CHECK(tet_cut_advance(&c, bad, han, &err) == -1);
    CHECK(tet_cut_end(&c, &err) == 0);
    CHECK(c.ntets == 1 && c.version == 0);
    tet_cut_destroy(&c);
  }
}

/* The seed's rules against the interpolated rest configuration. */
static void test_rest_rules(void) {
  double A[3] = {0.1, -0.2, 0.05}, B[3] = {1.3, 0.4, -0.2}, C[3] = {0.2, 0.9, 0.6};
  /* Edge: P at t = 0.3 on AB; current lengths stretched by 1.7. */
  double d = v3_dist(A, B), t = 0.3;
  CHECK_NEAR(tet_cut_rest_edge(d, 1.7 * t * d, 1.7 * (1 - t) * d), t * d, 1e-14);
  double l[3] = {0.2, 0.5, 0.3}, P[3];
  for (int k = 0; k < 3; k++) P[k] = l[0] * A[k] + l[1] * B[k] + l[2] * C[k];
  CHECK_NEAR(tet_cut_rest_face(v3_dist(A, B), v3_dist(B, C), v3_dist(A, C), l[0], l[1], l[2]), v3_dist(A, P), 1e-14);
}

/* ---- the PBD model with cutting ------------------------------------------- */

static void box_surface(mesh_t *m, double lx, double ly, double lz) {
  static const uint32_t T[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                    {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  mesh_alloc(m, 8, 12, NULL);
  for (int i = 0; i < 8; i++) v3_set(m->pos + 3 * i, lx * ((i & 1) ^ (i >> 1 & 1)), ly * (i >> 1 & 1), lz * (i >> 2));
  memcpy(m->tris, T, sizeof T);
}

/* A 30 x 4 x 4 cm bar, XPBD, both ends (x = 0 and x = 0.3) fixed. */
static model_t *bar_model(const mesh_t *surf, scene_organ_t *cfg) {
  memset(cfg, 0, sizeof *cfg);
  snprintf(cfg->name, sizeof cfg->name, "bar");
  snprintf(cfg->model, sizeof cfg->model, "xpbd");
  cfg->material = (scene_material_t){.mass = 0.3,
                                     .home_damping = 0.002,
                                     .distance_stiffness = 1,
                                     .volume_stiffness = 1,
                                     .distance_compliance = 1e-4,
                                     .volume_compliance = 1e-7};
  cfg->solver = (scene_solver_t){.substeps = 0, .iterations = 5, .tet_size = 0.01};
  model_params_t mp = {.cfg = cfg, .surface = surf, .gravity = {0, 0, -9.81}, .dt = 0.005, .tool_stiffness = 0};
  verr_t err;
  model_t *m = model_pbd_create(&mp, &err);
  if (!m) {
    fprintf(stderr, "bar model: %s\n", err.msg);
    return NULL;
  }
  pbd_t *s = model_pbd_solver(m);
  for (size_t i = 0; i < s->n; i++)
    if (s->x_rest[3 * i] < 1e-6 || s->x_rest[3 * i] > 0.3 - 1e-6) pbd_fix_node(s, i);
  return m;
}

/* Lowest z of the nodes within 2 cm of the middle, minus their rest z. */
static double middle_sag(const model_t *m) {
  double sag = 0;
  for (size_t i = 0; i < m->nnodes; i++)
    if (fabs(m->x_rest[3 * i] - 0.15) < 0.02) sag = fmin(sag, m->x[3 * i + 2] - m->x_rest[3 * i + 2]);
  return sag;
}

static int model_finite(const model_t *m) {
  for (size_t k = 0; k < 3 * m->nnodes; k++)
    if (!isfinite(m->x[k]) || !isfinite(m->v[k])) return 0;
  for (size_t k = 0; k < 3 * m->nsurf; k++)
    if (!isfinite(m->surf_x[k])) return 0;
  return 1;
}

static void test_model_cut(void) {
  mesh_t surf;
  box_surface(&surf, 0.3, 0.04, 0.04);
  scene_organ_t cfg;
  model_t *ref = bar_model(&surf, &cfg), *m = bar_model(&surf, &cfg);
  CHECK(ref && m);
  if (!ref || !m) {
    model_destroy(ref);
    model_destroy(m);
    mesh_free(&surf);
    return;
  }
  /* No cutting structures unless a cut starts (or the scene has a scalpel):
   * the models hold none, the cutter copies no mesh until then. */
  verr_t err;
  tet_model_cut_t *tc = tet_model_cut_create(m, &err);
  CHECK(tc != NULL && tet_model_cut_mesh(tc) == NULL && tet_model_cut_mesh(NULL) == NULL);
  CHECK(model_pbd_surface_attr(m) == NULL);
  CHECK(tet_model_cut_end(tc, &err) == 0 && tet_model_cut_mesh(tc) == NULL);
  size_t tets0 = m->ntets, tris0 = m->nsurf_tris;
  int ok = 1;
  /* Let both settle a little, then cut the middle with a vertical blade
   * swept across y while the model keeps stepping. */
  for (int k = 0; k < 20; k++) ok &= ref->ops->step(ref, 0.005) == 0 && m->ops->step(m, 0.005) == 0;
  int split = 0;
  for (int k = 0; k <= 8; k++) {
    double y = -0.01 + 0.06 * k / 8;
    double tip[3] = {0.153, y, -0.02}, han[3] = {0.153, y, 0.07};
    int n = tet_model_cut_advance(tc, tip, han, &err);
    CHECK(n >= 0);
    split += n > 0 ? n : 0;
    ok &= m->ops->step(m, 0.005) == 0 && ref->ops->step(ref, 0.005) == 0;
  }
  int n = tet_model_cut_end(tc, &err);
  CHECK(n >= 0);
  const tet_cut_t *c = tet_model_cut_mesh(tc);
  CHECK(c != NULL);
  if (!c) {
    tet_model_cut_destroy(tc);
    model_destroy(ref);
    model_destroy(m);
    mesh_free(&surf);
    return;
  }
  CHECK(split > 0);
  CHECK(m->topology_version > 0);
  CHECK(pieces(c) == 2);
  CHECK(m->ntets > tets0 && m->nsurf_tris > tris0 && m->nnodes == c->n);
  CHECK(model_pbd_surface_attr(m) != NULL);
  /* The surface is the cutter's boundary, closed and manifold. */
  size_t nf;
  CHECK(boundary_defects(c, &nf) == 0 && nf == m->nsurf_tris);
  /* 1 s after the cut. */
  for (int k = 0; k < 200; k++) ok &= ref->ops->step(ref, 0.005) == 0 && m->ops->step(m, 0.005) == 0;
  CHECK(ok);
  CHECK(model_finite(m));
  pbd_errors_t e;
  pbd_errors(model_pbd_solver(m), &e);
  double s_ref = middle_sag(ref), s_cut = middle_sag(m);
  printf("  bar cut in the middle: %zu -> %zu tetrahedra, %zu -> %zu surface triangles; 1 s later the middle sags "
         "%.1f mm (uncut %.1f mm), %zu inverted, max strain %.3f\n",
         tets0, m->ntets, tris0, m->nsurf_tris, -1e3 * s_cut, -1e3 * s_ref, e.inverted, e.strain_max);
  CHECK(s_cut < 3 * s_ref && s_cut < -0.005);
  CHECK(e.inverted == 0);
  tet_model_cut_destroy(tc);
  model_destroy(ref);
  model_destroy(m);
  mesh_free(&surf);
}

int main(void) {
  test_classify();
  test_rest_rules();
  test_general_cases();
  test_partial_cases();
  test_box();
  test_model_cut();
  return check_report("test_tet_cut");
}
