/* SPDX-License-Identifier: Apache-2.0 */
/* volume_mesh: reading and writing offline tetrahedral meshes (see
 * volume_mesh.h); the format readers are volume_gmsh.c, volume_vtk.c and
 * volume_tetgen.c, which hand over node tags and corners as written. Here
 * the tags become indices and the mesh is checked and repaired. */
#include "volume_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tet_embed.h"
#include "vmath.h"
#include "volume_raw.h"

/* ---- tags -> indices, checks, repairs ---- */

typedef struct tag_ix {
  long long tag;
  uint32_t ix;
} tag_ix_t;

static int tag_cmp(const void *a, const void *b) {
  long long x = ((const tag_ix_t *)a)->tag, y = ((const tag_ix_t *)b)->tag;
  return x < y ? -1 : x > y;
}

static double signed_volume(const double *x, const uint32_t *c) {
  double u[3], v[3], w[3], n[3];
  v3_sub(u, x + 3 * (size_t)c[1], x + 3 * (size_t)c[0]);
  v3_sub(v, x + 3 * (size_t)c[2], x + 3 * (size_t)c[0]);
  v3_sub(w, x + 3 * (size_t)c[3], x + 3 * (size_t)c[0]);
  v3_cross(n, v, w);
  return v3_dot(u, n) / 6.0;
}

/* Corners by index, each tetrahedron checked for repeated corners. */
static int map_corners(const char *path, const volume_raw_t *r, uint32_t *tets, verr_t *err) {
  tag_ix_t *map = malloc(r->nnodes * sizeof *map + 1);
  if (!map) return verr_set(err, "%s: out of memory for %zu nodes", path, r->nnodes);
  for (size_t i = 0; i < r->nnodes; i++) map[i] = (tag_ix_t){r->tag[i], (uint32_t)i};
  qsort(map, r->nnodes, sizeof *map, tag_cmp);
  int rc = 0;
  for (size_t i = 1; i < r->nnodes && !rc; i++)
    if (map[i].tag == map[i - 1].tag) rc = verr_set(err, "%s: node %lld is defined twice", path, map[i].tag);
  for (size_t i = 0; i < r->ntets && !rc; i++)
    for (int k = 0; k < 4 && !rc; k++) {
      tag_ix_t key = {r->corner[4 * i + (size_t)k], 0};
      const tag_ix_t *hit = bsearch(&key, map, r->nnodes, sizeof *map, tag_cmp);
      if (!hit)
        rc = verr_set(err, "%s:%d: a tetrahedron names node %lld, which the file does not define", path, r->line[i],
                      key.tag);
      else
        tets[4 * i + (size_t)k] = hit->ix;
      for (int j = 0; j < k && !rc; j++)
        if (tets[4 * i + (size_t)j] == tets[4 * i + (size_t)k])
          rc = verr_set(err, "%s:%d: a tetrahedron names node %lld twice", path, r->line[i], key.tag);
    }
  free(map);
  return rc;
}

/* Orientation repaired, flat tetrahedra refused, unused nodes dropped. */
static int finish(const char *path, const volume_raw_t *r, uint32_t *tets, tet_mesh_t *out, volume_report_t *rep,
                  verr_t *err) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < 4 * r->ntets; i++)
    for (int k = 0; k < 3; k++) {
      double v = r->x[3 * (size_t)tets[i] + k];
      lo[k] = fmin(lo[k], v), hi[k] = fmax(hi[k], v);
    }
  double ext = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
  if (!(ext > 0)) return verr_set(err, "%s: the tetrahedra have no extent", path);
  /* A tetrahedron this flat has no stiffness to speak of and makes the
   * solvers divide by almost nothing. */
  double vmin = 1e-12 * ext * ext * ext;
  for (size_t i = 0; i < r->ntets; i++) {
    uint32_t *c = tets + 4 * i;
    double v = signed_volume(r->x, c);
    if (fabs(v) <= vmin)
      return verr_set(err, "%s:%d: a tetrahedron has (almost) no volume (%g, the mesh spans %g)", path, r->line[i], v,
                      ext);
    if (v < 0) {
      uint32_t t = c[2];
      c[2] = c[3];
      c[3] = t;
      rep->flipped++;
    }
  }
  uint32_t *new_ix = malloc(r->nnodes * sizeof *new_ix + 1);
  if (!new_ix) return verr_set(err, "%s: out of memory", path);
  for (size_t i = 0; i < r->nnodes; i++) new_ix[i] = UINT32_MAX;
  for (size_t i = 0; i < 4 * r->ntets; i++) new_ix[tets[i]] = 0;
  size_t nn = 0;
  for (size_t i = 0; i < r->nnodes; i++)
    if (new_ix[i] == 0) new_ix[i] = (uint32_t)nn++;
  out->x = malloc(3 * nn * sizeof *out->x + 1);
  if (!out->x) {
    free(new_ix);
    return verr_set(err, "%s: out of memory", path);
  }
  for (size_t i = 0; i < r->nnodes; i++)
    if (new_ix[i] != UINT32_MAX) memcpy(out->x + 3 * (size_t)new_ix[i], r->x + 3 * i, 3 * sizeof(double));
  for (size_t i = 0; i < 4 * r->ntets; i++) tets[i] = new_ix[tets[i]];
  free(new_ix);
  out->nnodes = nn;
  out->tets = tets;
  out->ntets = r->ntets;
  rep->unused = r->nnodes - nn;
  return 0;
}

static int ends_with(const char *s, const char *suffix) {
  size_t a = strlen(s), b = strlen(suffix);
  return a >= b && !strcmp(s + a - b, suffix);
}

int volume_path_known(const char *path) {
  return ends_with(path, ".msh") || ends_with(path, ".vtk") || ends_with(path, ".node") || ends_with(path, ".ele");
}

static int read_raw(const char *path, volume_raw_t *r, verr_t *err) {
  text_scan_t a, b;
  if (ends_with(path, ".node") || ends_with(path, ".ele")) {
    char node[4096], ele[4096];
    size_t stem = strlen(path) - (ends_with(path, ".ele") ? 4 : 5);
    if (stem + 6 > sizeof node) return verr_set(err, "%s: path too long", path);
    snprintf(node, sizeof node, "%.*s.node", (int)stem, path);
    snprintf(ele, sizeof ele, "%.*s.ele", (int)stem, path);
    if (text_scan_open(&a, node, '#', err)) return -1;
    if (text_scan_open(&b, ele, '#', err)) {
      text_scan_close(&a);
      return -1;
    }
    int rc = volume_read_tetgen(&a, &b, r, err);
    text_scan_close(&a);
    text_scan_close(&b);
    return rc;
  }
  int msh = ends_with(path, ".msh");
  if (!msh && !ends_with(path, ".vtk"))
    return verr_set(err, "%s: not a volume mesh name (.msh, .vtk, .node or .ele)", path);
  if (text_scan_open(&a, path, 0, err)) return -1;
  int rc = msh ? volume_read_msh(&a, r, err) : volume_read_vtk(&a, r, err);
  text_scan_close(&a);
  return rc;
}

int volume_import(const char *path, tet_mesh_t *out, volume_report_t *report, verr_t *err) {
  volume_report_t rep;
  memset(&rep, 0, sizeof rep);
  memset(out, 0, sizeof *out);
  volume_raw_t r;
  memset(&r, 0, sizeof r);
  uint32_t *tets = NULL;
  int rc = read_raw(path, &r, err);
  if (!rc && !r.ntets)
    rc = verr_set(err, "%s: no tetrahedra (%zu nodes, %zu other elements)", path, r.nnodes, r.skipped);
  if (!rc && !(tets = malloc(4 * r.ntets * sizeof *tets))) rc = verr_set(err, "%s: out of memory", path);
  if (!rc) rc = map_corners(path, &r, tets, err);
  if (!rc) rc = finish(path, &r, tets, out, &rep, err);
  if (!rc) {
    tets = NULL; /* out owns them */
    mesh_t surf;
    size_t bad = 0;
    verr_t e;
    if (tet_mesh_boundary(out, &surf, NULL, &bad, &e))
      rc = verr_set(err, "%s:%d: %s", path, r.line[bad], e.msg);
    else
      mesh_free(&surf);
  }
  if (!rc) {
    rep.nodes = out->nnodes;
    rep.tets = out->ntets;
    rep.skipped = r.skipped;
    rep.min_quality = INFINITY;
    for (size_t i = 0; i < out->ntets; i++) {
      rep.volume += tet_volume(out, out->x, i);
      rep.min_quality = fmin(rep.min_quality, tet_quality(out, out->x, i));
    }
    if (report) *report = rep;
  } else {
    tet_mesh_free(out);
  }
  free(tets);
  volume_raw_free(&r);
  return rc;
}
