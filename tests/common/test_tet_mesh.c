/* SPDX-License-Identifier: Apache-2.0 */
/* tet_mesh: the box grid (counts, orientation, volume, conforming faces), the
 * measures, and tet_mesh_build on generated cubes and spheres, on the organs in
 * assets/meshes and on the open tissue patch, which must fail clearly.
 * Built a second time with TET_TEST_SHARED as test_tet_mesh_shared: the real
 * third-party organs in ../shared/data/organs, skipping (77) when absent. */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_assets.h"
#include "mesh.h"
#include "mesh_import.h"
#include "tet_mesh.h"

typedef struct face {
  uint32_t v[3];
} face_t;

static int face_cmp(const void *pa, const void *pb) {
  const face_t *a = pa, *b = pb;
  for (int k = 0; k < 3; k++)
    if (a->v[k] != b->v[k]) return a->v[k] < b->v[k] ? -1 : 1;
  return 0;
}

static void sort3(uint32_t *v) {
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2 - i; j++)
      if (v[j] > v[j + 1]) {
        uint32_t s = v[j];
        v[j] = v[j + 1];
        v[j + 1] = s;
      }
}

/* Every face of every tetrahedron, sorted so equal faces are neighbours. The
 * caller frees the array (4 ntets faces). */
static face_t *all_faces(const tet_mesh_t *t) {
  face_t *f = malloc(4 * t->ntets * sizeof *f);
  if (!f) return NULL;
  static const int opp[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (size_t i = 0; i < t->ntets; i++)
    for (int k = 0; k < 4; k++) {
      face_t *g = f + 4 * i + k;
      for (int m = 0; m < 3; m++) g->v[m] = t->tets[4 * i + opp[k][m]];
      sort3(g->v);
    }
  qsort(f, 4 * t->ntets, sizeof *f, face_cmp);
  return f;
}

#ifndef TET_TEST_SHARED
/* A face used once must lie on the box's surface: all three nodes on one of
 * the six planes. A face used once inside would be half of a T-crack. */
static int on_box_boundary(const tet_mesh_t *t, const face_t *f, const double *lo, const double *hi) {
  for (int axis = 0; axis < 3; axis++)
    for (int side = 0; side < 2; side++) {
      double plane = side ? hi[axis] : lo[axis];
      int all = 1;
      for (int m = 0; m < 3; m++) all &= fabs(t->x[3 * (size_t)f->v[m] + axis] - plane) < 1e-12;
      if (all) return 1;
    }
  return 0;
}

static void test_box_grid(size_t nx, size_t ny, size_t nz, double h) {
  tet_mesh_t t;
  verr_t err = {{0}};
  CHECK(tet_mesh_box_grid(nx, ny, nz, h, &t, &err) == 0);
  CHECK(t.nnodes == nx * ny * nz);
  CHECK(t.ntets == 5 * (nx - 1) * (ny - 1) * (nz - 1));
  double vol = 0, vmin = INFINITY, qmin = 1;
  for (size_t i = 0; i < t.ntets; i++) {
    double v = tet_volume(&t, t.x, i);
    vol += v;
    if (v < vmin) vmin = v;
    double q = tet_quality(&t, t.x, i);
    if (q < qmin) qmin = q;
  }
  CHECK(vmin > 0);
  double box = (double)(nx - 1) * (double)(ny - 1) * (double)(nz - 1) * h * h * h;
  CHECK_NEAR(vol, box, 1e-12 * box);
  /* The 5-split's corner tetrahedra have radius ratio about 0.73, the central one 1. */
  CHECK(qmin > 0.7);

  face_t *f = all_faces(&t);
  CHECK(f != NULL);
  if (f) {
    double lo[3] = {0, 0, 0}, hi[3] = {(double)(nx - 1) * h, (double)(ny - 1) * h, (double)(nz - 1) * h};
    size_t shared = 0, boundary = 0, bad = 0;
    for (size_t i = 0; i < 4 * t.ntets;) {
      size_t j = i + 1;
      while (j < 4 * t.ntets && !face_cmp(f + i, f + j)) j++;
      if (j - i == 2)
        shared++;
      else if (j - i == 1 && on_box_boundary(&t, f + i, lo, hi))
        boundary++;
      else
        bad++;
      i = j;
    }
    CHECK(bad == 0);
    /* The box surface has 2 triangles per boundary cell face. */
    size_t cx = nx - 1, cy = ny - 1, cz = nz - 1;
    CHECK(boundary == 4 * (cx * cy + cy * cz + cz * cx));
    CHECK(2 * shared + boundary == 4 * t.ntets);
    free(f);
  }
  tet_mesh_free(&t);
  CHECK(t.x == NULL && t.tets == NULL && t.nnodes == 0);
}

static void test_box_grid_errors(void) {
  tet_mesh_t t;
  verr_t err = {{0}};
  CHECK(tet_mesh_box_grid(1, 5, 5, 0.1, &t, &err) < 0);
  CHECK(strstr(err.msg, "at least 2") != NULL);
  CHECK(tet_mesh_box_grid(3, 3, 3, 0, &t, &err) < 0);
  CHECK(tet_mesh_box_grid(3, 3, 3, NAN, &t, &err) < 0);
  CHECK(tet_mesh_box_grid(100000, 100000, 1000, 0.1, &t, &err) < 0);
}

/* ---- measures ----------------------------------------------------------- */

static void test_measures(void) {
  /* A regular tetrahedron scores 1, the cube-corner one 0.732, flat and inverted 0. */
  double x[] = {0, 0, 0, 1, 0, 0, 0.5, sqrt(3) / 2, 0, 0.5, sqrt(3) / 6, sqrt(2.0 / 3)};
  uint32_t q[] = {0, 1, 2, 3};
  tet_mesh_t t = {4, 1, x, q};
  CHECK_NEAR(tet_quality(&t, x, 0), 1, 1e-12);
  CHECK_NEAR(tet_volume(&t, x, 0), 1 / (6 * sqrt(2)), 1e-12);
  double c[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  CHECK_NEAR(tet_volume(&t, c, 0), 1.0 / 6, 1e-15);
  CHECK_NEAR(tet_quality(&t, c, 0), 3 * (0.5 / (1.5 + sqrt(3) / 2)) / (sqrt(3) / 2), 1e-12);
  double flat[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  CHECK(tet_quality(&t, flat, 0) == 0);
  CHECK(tet_volume(&t, flat, 0) == 0);
  double inv[] = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};
  CHECK_NEAR(tet_volume(&t, inv, 0), -1.0 / 6, 1e-15);
  CHECK(tet_quality(&t, inv, 0) == 0);
  /* Collapsed to a point: no NaN. */
  double pt[12] = {0};
  CHECK(tet_quality(&t, pt, 0) == 0);
  /* A sliver (four nearly coplanar points) scores near 0. */
  double sl[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1e-4};
  double qs = tet_quality(&t, sl, 0);
  CHECK(qs >= 0 && qs < 1e-3);
}

#endif

/* ---- generated surfaces -------------------------------------------------- */

#ifndef TET_TEST_SHARED
/* The surface of an n x n x n lattice cube, triangulated with outward
 * (counter-clockwise) triangles and welded. shape 0: the cube [-s, s]^3; 1: the
 * same vertices pushed onto the sphere of radius s. Then moved by `centre`. */
static int make_cube_sphere(mesh_t *m, int n, int sphere, double s, const double *centre) {
  size_t side = (size_t)n + 1;
  uint32_t *id = malloc(side * side * side * sizeof *id);
  if (!id) return -1;
  size_t nv = 0;
  for (size_t k = 0; k < side; k++)
    for (size_t j = 0; j < side; j++)
      for (size_t i = 0; i < side; i++) {
        int on = i == 0 || j == 0 || k == 0 || i == (size_t)n || j == (size_t)n || k == (size_t)n;
        id[i + side * (j + side * k)] = on ? (uint32_t)nv++ : UINT32_MAX;
      }
  if (mesh_alloc(m, nv, 12 * (size_t)n * (size_t)n, NULL)) {
    free(id);
    return -1;
  }
  for (size_t k = 0; k < side; k++)
    for (size_t j = 0; j < side; j++)
      for (size_t i = 0; i < side; i++) {
        uint32_t v = id[i + side * (j + side * k)];
        if (v == UINT32_MAX) continue;
        double p[3] = {2.0 * (double)i / n - 1, 2.0 * (double)j / n - 1, 2.0 * (double)k / n - 1};
        double r = sphere ? sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) : 1;
        for (int a = 0; a < 3; a++) m->pos[3 * v + a] = s * p[a] / r + centre[a];
      }
  /* Each face: the fixed axis and its value, and axes u, v with u x v outward. */
  static const int faces[6][4] = {{0, 0, 2, 1}, {0, 1, 1, 2}, {1, 0, 0, 2}, {1, 1, 2, 0}, {2, 0, 1, 0}, {2, 1, 0, 1}};
  size_t t = 0;
  for (int f = 0; f < 6; f++)
    for (int a = 0; a < n; a++)
      for (int b = 0; b < n; b++) {
        uint32_t corner[4];
        for (int c = 0; c < 4; c++) {
          size_t l[3];
          l[faces[f][0]] = faces[f][1] ? (size_t)n : 0;
          l[faces[f][2]] = (size_t)(a + (c == 1 || c == 2));
          l[faces[f][3]] = (size_t)(b + (c >= 2));
          corner[c] = id[l[0] + side * (l[1] + side * l[2])];
        }
        uint32_t tri[6] = {corner[0], corner[1], corner[2], corner[0], corner[2], corner[3]};
        memcpy(m->tris + 3 * t, tri, sizeof tri);
        t += 2;
      }
  free(id);
  return 0;
}

#endif

/* How many tetrahedra are face-connected (union-find over shared faces); also
 * checks no face is shared by more than two tetrahedra. */
static size_t find_root(size_t *parent, size_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

static size_t tet_components(const tet_mesh_t *t, size_t *overshared) {
  *overshared = 0;
  face_t *f = all_faces(t);
  size_t *owner = malloc(4 * t->ntets * sizeof *owner), *parent = malloc(t->ntets * sizeof *parent);
  if (!f || !owner || !parent) {
    free(f), free(owner), free(parent);
    return 0;
  }
  /* all_faces sorts, losing which tetrahedron a face came from: rebuild the
   * owner by searching each tetrahedron's faces in the sorted array. */
  for (size_t i = 0; i < t->ntets; i++) parent[i] = i;
  static const int opp[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  size_t nf = 4 * t->ntets;
  size_t *first = owner; /* per sorted face slot: first tetrahedron seen, or SIZE_MAX */
  for (size_t i = 0; i < nf; i++) first[i] = SIZE_MAX;
  for (size_t i = 0; i < t->ntets; i++)
    for (int k = 0; k < 4; k++) {
      face_t g;
      for (int m = 0; m < 3; m++) g.v[m] = t->tets[4 * i + opp[k][m]];
      sort3(g.v);
      face_t *hit = bsearch(&g, f, nf, sizeof *f, face_cmp);
      while (hit > f && !face_cmp(hit - 1, &g)) hit--; /* first of the run */
      size_t slot = (size_t)(hit - f);
      if (first[slot] == SIZE_MAX)
        first[slot] = i;
      else
        parent[find_root(parent, i)] = find_root(parent, first[slot]);
    }
  for (size_t i = 0; i + 2 < nf; i++) *overshared += !face_cmp(f + i, f + i + 2);
  size_t comps = 0;
  for (size_t i = 0; i < t->ntets; i++) comps += find_root(parent, i) == i;
  free(f), free(owner), free(parent);
  return comps;
}

/* Signed volume about the bounding box centre: the same as mesh_signed_volume
 * for a closed surface, but without its cancellation far from the origin, and
 * the reference point tet_mesh_build uses for open surfaces. */
static double signed_volume_centred(const mesh_t *m) {
  double lo[3], hi[3], c[3], v = 0;
  mesh_bounds(m, lo, hi);
  for (int k = 0; k < 3; k++) c[k] = 0.5 * (lo[k] + hi[k]);
  for (size_t t = 0; t < m->ntris; t++) {
    double p[3][3];
    for (int i = 0; i < 3; i++)
      for (int k = 0; k < 3; k++) p[i][k] = m->pos[3 * (size_t)m->tris[3 * t + i] + k] - c[k];
    v += p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) - p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
         p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]);
  }
  return v / 6;
}

typedef struct build_expect {
  double min_quality;   /* every tetrahedron at least this good */
  double volume_tol;    /* |V_tets / V_surface - 1| at most this */
  double reproduce_tol; /* embedding error at rest, relative to 1 + |vertex| */
  int one_component;
} build_expect_t;

/* Builds, then checks the contract: positive tetrahedra, quality, volume, the
 * report against recomputed figures, the embedding reproducing every vertex at
 * rest and following an affine map of the nodes exactly. Returns the report. */
static tet_build_report_t check_build(const char *what, const mesh_t *m, double edge, const build_expect_t *ex) {
  tet_mesh_t t;
  tet_embedding_t e;
  tet_build_report_t r;
  verr_t err = {{0}};
  int rc = tet_mesh_build(m, edge, &t, &e, &r, &err);
  CHECK(rc == 0);
  if (rc) {
    fprintf(stderr, "%s: %s\n", what, err.msg);
    memset(&r, 0, sizeof r);
    return r;
  }
  CHECK(t.nnodes == r.nodes && t.ntets == r.tets);
  CHECK(r.tets >= 1000 || edge > 0);
  CHECK(r.tets <= 200000);
  double vol = 0, qmin = 1, vmin = INFINITY;
  for (size_t i = 0; i < t.ntets; i++) {
    double v = tet_volume(&t, t.x, i);
    vol += v;
    vmin = fmin(vmin, v);
    qmin = fmin(qmin, tet_quality(&t, t.x, i));
  }
  CHECK(vmin > 0);
  CHECK(qmin >= ex->min_quality);
  CHECK_NEAR(r.min_quality, qmin, 1e-12);
  CHECK(r.mean_quality >= r.min_quality && r.mean_quality <= 1);
  CHECK_NEAR(r.volume, vol, 1e-9 * vol);
  CHECK_NEAR(r.surface_volume, signed_volume_centred(m), 1e-9 * fabs(r.surface_volume));
  CHECK_NEAR(r.volume / fabs(r.surface_volume), 1, ex->volume_tol);
  CHECK(r.seconds > 0 && r.seconds < 30);
  /* Every node is used by some tetrahedron (the array was compacted). */
  unsigned char *used = calloc(t.nnodes, 1);
  size_t unused = 0;
  if (used) {
    for (size_t i = 0; i < 4 * t.ntets; i++) used[t.tets[i]] = 1;
    for (size_t v = 0; v < t.nnodes; v++) unused += !used[v];
    free(used);
  }
  CHECK(unused == 0);
  size_t over, comps = tet_components(&t, &over);
  CHECK(over == 0);
  if (ex->one_component) CHECK(comps == 1);

  /* Embedding: at rest every vertex is reproduced; weights finite and the
   * outside count matches the weights (a contained vertex has none below -eps). */
  CHECK(e.nsurf == m->nverts);
  double *sx = malloc(3 * m->nverts * sizeof *sx), *xn = malloc(3 * t.nnodes * sizeof *xn);
  size_t negative = 0;
  double worst = 0, min_w = 0;
  if (sx && xn) {
    tet_embedding_apply(&e, &t, t.x, sx);
    for (size_t v = 0; v < m->nverts; v++) {
      const double *p = m->pos + 3 * v;
      double err_v = 0, mag = 1 + fabs(p[0]) + fabs(p[1]) + fabs(p[2]);
      for (int k = 0; k < 3; k++) err_v = fmax(err_v, fabs(sx[3 * v + k] - p[k]) / mag);
      worst = fmax(worst, err_v);
      double wmin = INFINITY, wsum = 0;
      for (int k = 0; k < 4; k++) {
        CHECK(isfinite(e.bary[4 * v + k]));
        wmin = fmin(wmin, e.bary[4 * v + k]);
        wsum += e.bary[4 * v + k];
      }
      CHECK(e.tet[v] < t.ntets);
      CHECK_NEAR(wsum, 1, 1e-12);
      negative += wmin < -1e-9;
      min_w = fmin(min_w, wmin);
    }
    CHECK(worst <= ex->reproduce_tol);
    CHECK(r.outside_vertices <= m->nverts);
    CHECK(negative <= r.outside_vertices);
    /* Extrapolation stays mild: outside vertices are within about a cell. */
    CHECK(min_w > -2);

    /* An affine map of the nodes (rotation, shear, stretch, shift) moves the
     * embedded surface by the same map. */
    const double A[9] = {0.8, -0.6, 0.1, 0.6, 0.8, -0.2, 0.05, 0.3, 1.3}, s[3] = {0.3, -1.2, 2.5};
    for (size_t v = 0; v < t.nnodes; v++)
      for (int i = 0; i < 3; i++)
        xn[3 * v + i] = A[3 * i] * t.x[3 * v] + A[3 * i + 1] * t.x[3 * v + 1] + A[3 * i + 2] * t.x[3 * v + 2] + s[i];
    tet_embedding_apply(&e, &t, xn, sx);
    double worst_aff = 0;
    for (size_t v = 0; v < m->nverts; v++) {
      const double *p = m->pos + 3 * v;
      double mag = 1 + fabs(p[0]) + fabs(p[1]) + fabs(p[2]);
      for (int i = 0; i < 3; i++) {
        double want = A[3 * i] * p[0] + A[3 * i + 1] * p[1] + A[3 * i + 2] * p[2] + s[i];
        worst_aff = fmax(worst_aff, fabs(sx[3 * v + i] - want) / mag);
      }
    }
    CHECK(worst_aff <= 4 * ex->reproduce_tol);
  }
  CHECK(sx && xn);
  free(sx);
  free(xn);
  printf("%-28s %7zu nodes %7zu tets %6.3f s  quality min %.3f mean %.3f  volume ratio %.4f  outside %zu/%zu "
         "(min weight %.3f)  components %zu  rest error %.1e\n",
         what, r.nodes, r.tets, r.seconds, r.min_quality, r.mean_quality, r.volume / fabs(r.surface_volume),
         r.outside_vertices, m->nverts, min_w, comps, worst);
  tet_mesh_free(&t);
  tet_embedding_free(&e);
  return r;
}

#ifndef TET_TEST_SHARED
static const build_expect_t generated = {0.25, 0.04, 1e-12, 1};

static void test_build_generated(void) {
  mesh_t m;
  const double origin[3] = {0, 0, 0}, off[3] = {0.31, -0.17, 0.05};
  /* The unit cube: the grid's faces land off the cube's, snapping fixes it. */
  CHECK(make_cube_sphere(&m, 6, 0, 0.5, off) == 0);
  check_build("cube", &m, 0, &generated);
  check_build("cube, edge 0.05", &m, 0.05, &generated);
  mesh_free(&m);

  CHECK(make_cube_sphere(&m, 12, 1, 1.0, origin) == 0);
  tet_build_report_t r = check_build("sphere", &m, 0, &generated);
  CHECK(r.tets >= 1000 && r.tets < 5000); /* automatic size: refined from 8 cells to ~1,000 tets */
  r = check_build("sphere, edge 0.1", &m, 0.1, &generated);
  CHECK(r.tets > 15000);
  /* Inside out (every triangle reversed): the winding number is -1 inside and
   * still classifies; the reported surface volume is negative. */
  for (size_t t = 0; t < m.ntris; t++) {
    uint32_t s = m.tris[3 * t + 1];
    m.tris[3 * t + 1] = m.tris[3 * t + 2];
    m.tris[3 * t + 2] = s;
  }
  r = check_build("sphere, inside out", &m, 0, &generated);
  CHECK(r.surface_volume < 0);
  mesh_free(&m);

  /* Far from the origin (kilometres away, 5 cm across): local coordinates keep
   * the digits; reproduction is relative to the coordinates' size. */
  const double far[3] = {1000, -2000, 500};
  CHECK(make_cube_sphere(&m, 12, 1, 0.05, far) == 0);
  check_build("sphere at 2 km", &m, 0, &generated);

  /* Holes: dropping every 40th triangle (2.5 % of the surface, spread all
   * over) leaves a winding number near 1 inside, so the mesh is the same. */
  mesh_t holed;
  CHECK(mesh_copy(&holed, &m, NULL) == 0);
  size_t kept = 0;
  for (size_t t = 0; t < holed.ntris; t++)
    if (t % 40 != 7) memmove(holed.tris + 3 * kept++, holed.tris + 3 * t, 3 * sizeof *holed.tris);
  holed.ntris = kept;
  build_expect_t holes = generated;
  holes.volume_tol = 0.06; /* the holed surface's own signed volume is short by the holes */
  check_build("sphere at 2 km, holes", &holed, 0, &holes);
  /* A whole cap missing (everything above z = 0.7 r): still a solid. */
  kept = 0;
  for (size_t t = 0; t < m.ntris; t++) {
    double z = 0;
    for (int k = 0; k < 3; k++) z += m.pos[3 * (size_t)m.tris[3 * t + k] + 2] - far[2];
    if (z / 3 < 0.7 * 0.05) memcpy(holed.tris + 3 * kept++, m.tris + 3 * t, 3 * sizeof *holed.tris);
  }
  holed.ntris = kept;
  tet_mesh_t t;
  tet_embedding_t e;
  tet_build_report_t rc;
  verr_t err = {{0}};
  CHECK(tet_mesh_build(&holed, 0, &t, &e, &rc, &err) == 0);
  CHECK(rc.tets > 1000);
  /* The cap is 6 % of the ball, and the region near the hole sees a winding
   * number below 1/2: most of the cap is left out, the rest is filled. */
  double ball = 4.0 / 3 * 3.14159265358979 * 1.25e-4;
  CHECK(rc.volume > 0.88 * ball && rc.volume < 1.01 * ball);
  printf("sphere with its cap cut off: %zu tets, volume %.4g (ball %.4g)\n", rc.tets, rc.volume, ball);
  tet_mesh_free(&t);
  tet_embedding_free(&e);
  mesh_free(&holed);
  mesh_free(&m);
}

static void test_build_errors(void) {
  tet_mesh_t t;
  tet_embedding_t e;
  tet_build_report_t r;
  verr_t err = {{0}};
  mesh_t empty = {0, 0, NULL, NULL};
  CHECK(tet_mesh_build(&empty, 0, &t, &e, &r, &err) < 0);
  CHECK(strstr(err.msg, "empty") != NULL);
  CHECK(t.x == NULL && t.tets == NULL && e.tet == NULL && e.bary == NULL);

  /* A flat open square: encloses nothing. */
  mesh_t sq;
  CHECK(mesh_alloc(&sq, 4, 2, NULL) == 0);
  const double p[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const uint32_t tr[6] = {0, 1, 2, 0, 2, 3};
  memcpy(sq.pos, p, sizeof p);
  memcpy(sq.tris, tr, sizeof tr);
  err.msg[0] = 0;
  CHECK(tet_mesh_build(&sq, 0, &t, &e, &r, &err) < 0);
  CHECK(strstr(err.msg, "nothing is inside") != NULL);
  printf("flat square: %s\n", err.msg);
  sq.pos[1] = NAN;
  CHECK(tet_mesh_build(&sq, 0, &t, &e, &r, &err) < 0);
  CHECK(strstr(err.msg, "finite") != NULL || strstr(err.msg, "nan") != NULL || strstr(err.msg, "NaN") != NULL);
  printf("NaN vertex: %s\n", err.msg);
  mesh_free(&sq);

  mesh_t m;
  const double origin[3] = {0, 0, 0};
  CHECK(make_cube_sphere(&m, 8, 1, 1.0, origin) == 0);
  CHECK(tet_mesh_build(&m, 0.01, &t, &e, &r, &err) < 0);
  CHECK(strstr(err.msg, "too many") != NULL);
  printf("edge 0.01 on a unit sphere: %s\n", err.msg);
  CHECK(tet_mesh_build(&m, 5, &t, &e, &r, &err) < 0);
  CHECK(strstr(err.msg, "too coarse") != NULL);
  printf("edge 5 on a unit sphere: %s\n", err.msg);
  CHECK(tet_mesh_build(&m, -1, &t, &e, &r, &err) < 0);
  CHECK(tet_mesh_build(&m, NAN, &t, &e, &r, &err) < 0);
  /* A bad index is refused before anything reads through it. */
  m.tris[5] = (uint32_t)m.nverts;
  CHECK(tet_mesh_build(&m, 0, &t, &e, &r, &err) < 0);
  mesh_free(&m);
}

#endif

static int is_obj(const struct dirent *d) {
  size_t n = strlen(d->d_name);
  return n > 4 && !strcmp(d->d_name + n - 4, ".obj");
}

static int by_name(const struct dirent **a, const struct dirent **b) { return strcmp((*a)->d_name, (*b)->d_name); }

/* Every .obj in dir builds with the expectations, except `fails` (which must
 * fail naming the empty inside). Returns the number of files, -1 without dir. */
static int build_dir(const char *dir, const char *fails, const build_expect_t *ex) {
  struct dirent **list = NULL;
  int n = scandir(dir, &list, is_obj, by_name);
  if (n < 0) return -1;
  for (int i = 0; i < n; i++) {
    char path[4096 + 256]; /* dir is at most 4096 bytes, a name at most 256 */
    snprintf(path, sizeof path, "%s/%s", dir, list[i]->d_name);
    mesh_t m;
    verr_t err = {{0}};
    int rc = mesh_import(path, &m, &err);
    CHECK(rc == 0);
    if (!rc) {
      if (fails && !strcmp(list[i]->d_name, fails)) {
        tet_mesh_t t;
        tet_embedding_t e;
        tet_build_report_t r;
        CHECK(tet_mesh_build(&m, 0, &t, &e, &r, &err) < 0);
        CHECK(strstr(err.msg, "nothing is inside") != NULL);
        printf("%-28s fails as it should: %s\n", list[i]->d_name, err.msg);
      } else {
        check_build(list[i]->d_name, &m, 0, ex);
      }
      mesh_free(&m);
    } else {
      fprintf(stderr, "%s\n", err.msg);
    }
    free(list[i]);
  }
  free(list);
  return n;
}

#ifndef TET_TEST_SHARED
int main(void) {
  test_box_grid(30, 5, 5, 0.01); /* the BarDemo bar: 750 nodes, 2,320 tetrahedra */
  {
    tet_mesh_t t;
    CHECK(tet_mesh_box_grid(30, 5, 5, 0.01, &t, NULL) == 0);
    CHECK(t.nnodes == 750 && t.ntets == 2320);
    tet_mesh_free(&t);
  }
  test_box_grid(2, 2, 2, 1.0);
  test_box_grid(4, 3, 6, 0.25);
  test_box_grid_errors();
  test_measures();
  test_build_generated();
  test_build_errors();

  /* The generated organs: snapping keeps every tetrahedron at radius ratio >= 0.25. */
  const char *dir = test_asset("meshes");
  const build_expect_t organs = {0.25, 0.05, 1e-12, 1};
  int n = build_dir(dir, "tissue_block.obj", &organs);
  CHECK(n >= 5);
  return check_report("test_tet_mesh");
}
#else
int main(void) {
  const char *shared = getenv("VISCERA_SHARED_DIR");
  char dir[4096];
  snprintf(dir, sizeof dir, "%s/data/organs", shared ? shared : "");
  DIR *d = shared ? opendir(dir) : NULL;
  if (!d) {
    printf("test_tet_mesh_shared: %s absent, skipped\n", dir);
    return 77;
  }
  closedir(d);
  /* Real meshes: liver-smooth.obj has a 0.6 degree sliver triangle, liver2.obj
   * sits 15 units from the origin; the grid does not care about either. */
  const build_expect_t organs = {0.25, 0.08, 1e-12, 1};
  int n = build_dir(dir, NULL, &organs);
  CHECK(n >= 2);
  return check_report("test_tet_mesh_shared");
}
#endif
