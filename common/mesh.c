/* SPDX-License-Identifier: Apache-2.0 */
#include "mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"

int mesh_alloc(mesh_t *m, size_t nverts, size_t ntris, verr_t *err) {
  memset(m, 0, sizeof *m);
  if (nverts > (SIZE_MAX / 3 / sizeof(double)) || ntris > (SIZE_MAX / 3 / sizeof(uint32_t)) || nverts > UINT32_MAX)
    return verr_set(err, "mesh too large: %zu vertices, %zu triangles", nverts, ntris);
  m->pos = calloc(nverts * 3 + 1, sizeof(double));
  m->tris = calloc(ntris * 3 + 1, sizeof(uint32_t));
  if (!m->pos || !m->tris) {
    mesh_free(m);
    return verr_set(err, "out of memory for mesh of %zu vertices, %zu triangles", nverts, ntris);
  }
  m->nverts = nverts;
  m->ntris = ntris;
  return 0;
}

void mesh_free(mesh_t *m) {
  free(m->pos);
  free(m->tris);
  memset(m, 0, sizeof *m);
}

int mesh_copy(mesh_t *dst, const mesh_t *src, verr_t *err) {
  if (mesh_alloc(dst, src->nverts, src->ntris, err)) return -1;
  memcpy(dst->pos, src->pos, src->nverts * 3 * sizeof(double));
  memcpy(dst->tris, src->tris, src->ntris * 3 * sizeof(uint32_t));
  return 0;
}

void mesh_bounds(const mesh_t *m, double bmin[3], double bmax[3]) {
  for (int k = 0; k < 3; k++) {
    bmin[k] = m->nverts ? INFINITY : 0;
    bmax[k] = m->nverts ? -INFINITY : 0;
  }
  for (size_t i = 0; i < m->nverts; i++)
    for (int k = 0; k < 3; k++) {
      double x = m->pos[3 * i + k];
      if (x < bmin[k]) bmin[k] = x;
      if (x > bmax[k]) bmax[k] = x;
    }
}

void mesh_vertex_normals_f(size_t nverts, const float *pos, size_t ntris, const uint32_t *tris, float *out) {
  memset(out, 0, nverts * 3 * sizeof(float));
  for (size_t t = 0; t < ntris; t++) {
    const uint32_t *f = tris + 3 * t;
    if (f[0] >= nverts || f[1] >= nverts || f[2] >= nverts) continue;
    const float *a = pos + 3 * f[0], *b = pos + 3 * f[1], *c = pos + 3 * f[2];
    float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    /* The unnormalised cross product weights each face by its area. */
    float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; k++)
      for (int j = 0; j < 3; j++) out[3 * f[k] + j] += n[j];
  }
  for (size_t i = 0; i < nverts; i++) {
    float *n = out + 3 * i;
    float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 1e-30f) {
      n[0] /= len;
      n[1] /= len;
      n[2] /= len;
    }
  }
}

double mesh_signed_volume(const mesh_t *m) {
  double v = 0;
  for (size_t t = 0; t < m->ntris; t++) {
    const uint32_t *f = m->tris + 3 * t;
    double c[3];
    v3_cross(c, m->pos + 3 * f[1], m->pos + 3 * f[2]);
    v += v3_dot(m->pos + 3 * f[0], c);
  }
  return v / 6.0;
}

int mesh_validate(const mesh_t *m, const char *what, verr_t *err) {
  if (m->nverts == 0 || m->ntris == 0)
    return verr_set(err, "%s: mesh is empty (%zu vertices, %zu triangles)", what, m->nverts, m->ntris);
  for (size_t i = 0; i < m->nverts * 3; i++)
    if (!isfinite(m->pos[i]))
      return verr_set(err, "%s: vertex %zu has a non-finite coordinate (%g)", what, i / 3, m->pos[i]);
  for (size_t i = 0; i < m->ntris * 3; i++)
    if (m->tris[i] >= m->nverts)
      return verr_set(err, "%s: triangle %zu references vertex %u but the mesh has %zu", what, i / 3, m->tris[i],
                      m->nverts);
  return 0;
}

int mesh_write_obj(const mesh_t *m, const char *path, const char *comment, verr_t *err) {
  FILE *f = fopen(path, "w");
  if (!f) return verr_set(err, "%s: cannot open for writing", path);
  if (comment) fprintf(f, "# %s\n", comment);
  fprintf(f, "# %zu vertices, %zu triangles\n", m->nverts, m->ntris);
  for (size_t i = 0; i < m->nverts; i++)
    fprintf(f, "v %.9g %.9g %.9g\n", m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]);
  for (size_t t = 0; t < m->ntris; t++)
    fprintf(f, "f %u %u %u\n", m->tris[3 * t] + 1, m->tris[3 * t + 1] + 1, m->tris[3 * t + 2] + 1);
  if (fclose(f) != 0) return verr_set(err, "%s: write failed", path);
  return 0;
}
