/* SPDX-License-Identifier: Apache-2.0 */
#include "mesh_check.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"

/* Undirected edge (lo, hi) with how many faces use it and how many of those
 * traverse it lo -> hi; two faces agree on orientation when exactly one does. */
typedef struct edge_slot {
  uint64_t key; /* lo << 32 | hi; EDGE_EMPTY marks a free slot (lo < hi makes it impossible) */
  uint32_t uses;
  uint32_t forward;
} edge_slot_t;

#define EDGE_EMPTY UINT64_MAX

typedef struct edge_map {
  edge_slot_t *slot;
  size_t cap; /* power of two, at least twice the edges inserted */
  size_t count;
} edge_map_t;

static uint64_t mix64(uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return h;
}

static int edge_map_init(edge_map_t *e, size_t max_edges) {
  if (max_edges > SIZE_MAX / 4 / sizeof *e->slot) return -1;
  e->cap = 16;
  while (e->cap < 2 * max_edges) e->cap *= 2;
  e->count = 0;
  e->slot = malloc(e->cap * sizeof *e->slot);
  if (!e->slot) return -1;
  for (size_t i = 0; i < e->cap; i++) e->slot[i] = (edge_slot_t){EDGE_EMPTY, 0, 0};
  return 0;
}

static void edge_map_add(edge_map_t *e, uint32_t a, uint32_t b) {
  uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
  uint64_t key = (uint64_t)lo << 32 | hi;
  size_t h = (size_t)mix64(key) & (e->cap - 1);
  while (e->slot[h].key != EDGE_EMPTY && e->slot[h].key != key) h = (h + 1) & (e->cap - 1);
  edge_slot_t *s = &e->slot[h];
  if (s->key == EDGE_EMPTY) {
    s->key = key;
    e->count++;
  }
  s->uses++;
  s->forward += a == lo;
}

static uint32_t uf_find(uint32_t *parent, uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

static void uf_union(uint32_t *parent, uint32_t a, uint32_t b) {
  a = uf_find(parent, a);
  b = uf_find(parent, b);
  /* The smaller root wins, which keeps the result independent of face order. */
  if (a < b)
    parent[b] = a;
  else if (b < a)
    parent[a] = b;
}

typedef struct pos_key {
  uint64_t k[3];
} pos_key_t;

static int pos_key_cmp(const void *pa, const void *pb) {
  const pos_key_t *a = pa, *b = pb;
  for (int i = 0; i < 3; i++)
    if (a->k[i] != b->k[i]) return a->k[i] < b->k[i] ? -1 : 1;
  return 0;
}

/* Sorting exact bit patterns (with -0 folded into +0) gives a total order even
 * with NaNs, so equal positions end up adjacent. */
static int count_duplicates(const mesh_t *m, size_t *dups) {
  pos_key_t *keys = malloc((m->nverts + 1) * sizeof *keys);
  if (!keys) return -1;
  for (size_t i = 0; i < m->nverts; i++)
    for (int k = 0; k < 3; k++) {
      double x = m->pos[3 * i + k] == 0.0 ? 0.0 : m->pos[3 * i + k];
      memcpy(&keys[i].k[k], &x, sizeof x);
    }
  qsort(keys, m->nverts, sizeof *keys, pos_key_cmp);
  *dups = 0;
  for (size_t i = 1; i < m->nverts; i++) *dups += pos_key_cmp(&keys[i - 1], &keys[i]) == 0;
  free(keys);
  return 0;
}

static int face_degenerate(const mesh_t *m, const uint32_t *f) {
  if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) return 1;
  double e[3][3], c[3], lmax2 = 0;
  for (int i = 0; i < 3; i++) {
    v3_sub(e[i], m->pos + 3 * (size_t)f[(i + 1) % 3], m->pos + 3 * (size_t)f[i]);
    lmax2 = fmax(lmax2, v3_dot(e[i], e[i]));
  }
  v3_cross(c, e[0], e[1]);
  /* |c| = longest edge * height, so this compares height / longest edge. */
  return v3_norm(c) <= MESH_CHECK_DEGENERATE_REL * lmax2;
}

/* Smallest corner angle in degrees; atan2 stays accurate for slivers. */
static double face_min_angle(const mesh_t *m, const uint32_t *f) {
  double best = 180;
  for (int k = 0; k < 3; k++) {
    double u[3], w[3], c[3];
    const double *a = m->pos + 3 * (size_t)f[k];
    v3_sub(u, m->pos + 3 * (size_t)f[(k + 1) % 3], a);
    v3_sub(w, m->pos + 3 * (size_t)f[(k + 2) % 3], a);
    v3_cross(c, u, w);
    double ang = atan2(v3_norm(c), v3_dot(u, w)) * (180 / 3.14159265358979323846);
    if (ang < best) best = ang;
  }
  return best;
}

static int face_valid(const mesh_t *m, const uint32_t *f) {
  return f[0] < m->nverts && f[1] < m->nverts && f[2] < m->nverts;
}

int mesh_check(const mesh_t *m, mesh_report_t *r) {
  memset(r, 0, sizeof *r);
  edge_map_t em = {0};
  uint32_t *parent = malloc((m->nverts + 1) * sizeof *parent);
  unsigned char *used = calloc(m->nverts + 1, 1);
  if (!parent || !used || edge_map_init(&em, 3 * m->ntris) || count_duplicates(m, &r->duplicate_vertices)) {
    free(parent);
    free(used);
    free(em.slot);
    memset(r, 0, sizeof *r);
    return -1;
  }
  r->vertices = m->nverts;
  r->triangles = m->ntris;

  int any = 0;
  for (size_t i = 0; i < m->nverts; i++) {
    const double *p = m->pos + 3 * i;
    parent[i] = (uint32_t)i;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
      r->nonfinite_vertices++;
      continue;
    }
    for (int k = 0; k < 3; k++) {
      if (!any || p[k] < r->bmin[k]) r->bmin[k] = p[k];
      if (!any || p[k] > r->bmax[k]) r->bmax[k] = p[k];
    }
    any = 1;
  }
  double mid[3];
  for (int k = 0; k < 3; k++) {
    r->size[k] = r->bmax[k] - r->bmin[k];
    mid[k] = 0.5 * (r->bmin[k] + r->bmax[k]);
  }

  size_t faces = 0;
  r->min_angle_deg = 180;
  double vol6 = 0;
  for (size_t t = 0; t < m->ntris; t++) {
    const uint32_t *f = m->tris + 3 * t;
    if (!face_valid(m, f)) {
      r->bad_index_faces++;
      continue;
    }
    faces++;
    for (int k = 0; k < 3; k++) {
      used[f[k]] = 1;
      uint32_t a = f[k], b = f[(k + 1) % 3];
      if (a != b) edge_map_add(&em, a, b);
    }
    uf_union(parent, f[0], f[1]);
    uf_union(parent, f[1], f[2]);
    if (face_degenerate(m, f)) {
      r->degenerate_faces++;
    } else {
      double ang = face_min_angle(m, f);
      if (ang < r->min_angle_deg) r->min_angle_deg = ang;
    }
    /* Relative to the box centre: the same volume for a closed surface, with
     * less cancellation for meshes far from the origin. */
    double a[3], b[3], c[3], bc[3];
    v3_sub(a, m->pos + 3 * (size_t)f[0], mid);
    v3_sub(b, m->pos + 3 * (size_t)f[1], mid);
    v3_sub(c, m->pos + 3 * (size_t)f[2], mid);
    v3_cross(bc, b, c);
    vol6 += v3_dot(a, bc);
  }
  r->volume = vol6 / 6.0;

  size_t referenced = 0;
  for (size_t i = 0; i < m->nverts; i++) {
    if (!used[i]) continue;
    referenced++;
    r->components += uf_find(parent, (uint32_t)i) == i;
  }
  r->unreferenced_vertices = m->nverts - referenced;

  r->edges = em.count;
  for (size_t i = 0; i < em.cap; i++) {
    const edge_slot_t *s = &em.slot[i];
    if (s->key == EDGE_EMPTY) continue;
    if (s->uses == 1)
      r->boundary_edges++;
    else if (s->uses > 2)
      r->nonmanifold_edges++;
    else if (s->forward != 1)
      r->inconsistent_edges++;
  }
  if (r->min_angle_deg == 180) r->min_angle_deg = 0; /* no face to measure */
  r->closed = faces > 0 && r->boundary_edges == 0 && r->nonmanifold_edges == 0;
  r->euler = (long long)referenced - (long long)r->edges + (long long)faces;

  free(parent);
  free(used);
  free(em.slot);
  return 0;
}

/* One list serves both the count and the printout so they cannot disagree. */
static int problems(const mesh_report_t *r, FILE *f) {
  int n = 0;
#define PROBLEM(cond, ...)                                                                                             \
  do {                                                                                                                 \
    if (cond) {                                                                                                        \
      n++;                                                                                                             \
      if (f) {                                                                                                         \
        fputs("  - ", f);                                                                                              \
        fprintf(f, __VA_ARGS__);                                                                                       \
        fputc('\n', f);                                                                                                \
      }                                                                                                                \
    }                                                                                                                  \
  } while (0)
  PROBLEM(r->triangles == 0, "no triangles");
  PROBLEM(r->nonfinite_vertices, "%zu vertices with a NaN or infinite coordinate", r->nonfinite_vertices);
  PROBLEM(r->bad_index_faces, "%zu faces reference a vertex that does not exist", r->bad_index_faces);
  PROBLEM(r->boundary_edges, "%zu boundary edges: the surface is open (has holes or borders)", r->boundary_edges);
  PROBLEM(r->nonmanifold_edges, "%zu non-manifold edges (shared by more than two faces)", r->nonmanifold_edges);
  PROBLEM(r->inconsistent_edges, "%zu edges whose two faces are oriented inconsistently", r->inconsistent_edges);
  PROBLEM(r->degenerate_faces, "%zu degenerate faces (zero area or a repeated vertex)", r->degenerate_faces);
  PROBLEM(r->duplicate_vertices, "%zu vertices duplicate the position of another (not welded)", r->duplicate_vertices);
  PROBLEM(r->unreferenced_vertices, "%zu vertices are used by no face", r->unreferenced_vertices);
  PROBLEM(r->components > 1, "%zu separate connected pieces", r->components);
  PROBLEM(r->closed && r->inconsistent_edges == 0 && !(r->volume > 0),
          "signed volume %g is not positive: faces point inward", r->volume);
#undef PROBLEM
  return n;
}

int mesh_report_problems(const mesh_report_t *r) { return problems(r, NULL); }

void mesh_report_print(const mesh_report_t *r, FILE *f) {
  fprintf(f, "  vertices            %zu\n", r->vertices);
  fprintf(f, "  triangles           %zu\n", r->triangles);
  fprintf(f, "  bounds min          %.6g %.6g %.6g\n", r->bmin[0], r->bmin[1], r->bmin[2]);
  fprintf(f, "  bounds max          %.6g %.6g %.6g\n", r->bmax[0], r->bmax[1], r->bmax[2]);
  fprintf(f, "  size                %.6g x %.6g x %.6g\n", r->size[0], r->size[1], r->size[2]);
  fprintf(f, "  edges               %zu (boundary %zu, non-manifold %zu, inconsistent %zu)\n", r->edges,
          r->boundary_edges, r->nonmanifold_edges, r->inconsistent_edges);
  fprintf(f, "  closed              %s\n", r->closed ? "yes" : "no");
  fprintf(f, "  degenerate faces    %zu\n", r->degenerate_faces);
  fprintf(f, "  smallest angle      %.3g degrees\n", r->min_angle_deg);
  fprintf(f, "  duplicate vertices  %zu\n", r->duplicate_vertices);
  fprintf(f, "  unreferenced        %zu\n", r->unreferenced_vertices);
  fprintf(f, "  components          %zu\n", r->components);
  fprintf(f, "  euler (V-E+F)       %lld", r->euler);
  /* Genus only means something for a closed, consistently oriented 2-manifold. */
  if (r->closed && r->inconsistent_edges == 0 && r->components > 0)
    fprintf(f, " (genus %lld)", (long long)r->components - r->euler / 2);
  fputc('\n', f);
  if (r->closed)
    fprintf(f, "  volume              %.6g\n", r->volume);
  else
    fprintf(f, "  volume              undefined (surface not closed)\n");
  if (problems(r, NULL)) {
    fprintf(f, "  problems found:\n");
    problems(r, f);
  } else {
    fprintf(f, "  no problems found\n");
  }
}
