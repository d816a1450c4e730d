/* SPDX-License-Identifier: Apache-2.0 */
#include "mesh_admit.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_check.h"
#include "vmath.h"

/* One directed triangle edge, sorted by its undirected key to find the
 * triangle across it. */
typedef struct half {
  uint64_t key; /* lo << 32 | hi */
  uint32_t tri;
} half_t;

static int half_cmp(const void *a, const void *b) {
  const half_t *x = a, *y = b;
  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  return x->tri < y->tri ? -1 : x->tri > y->tri;
}

/* 1 when triangle t (flipped when flip[t]) runs a -> b. */
static int runs(const mesh_t *m, const unsigned char *flip, uint32_t t, uint32_t a, uint32_t b) {
  const uint32_t *f = m->tris + 3 * (size_t)t;
  for (int k = 0; k < 3; k++) {
    uint32_t p = f[k], q = f[(k + 1) % 3];
    if (flip[t] ? (q == a && p == b) : (p == a && q == b)) return 1;
  }
  return 0;
}

/* Re-winds triangles to agree with their neighbours, starting from
 * triangle 0 of each part (the mesh is manifold: at most two triangles per
 * edge). *flipped counts the re-wound ones. 0, -1 out of memory, -2 not
 * orientable. */
static int orient(mesh_t *m, size_t *flipped) {
  size_t nt = m->ntris, nh = 3 * nt;
  half_t *h = malloc(nh * sizeof *h);
  uint32_t *across = malloc(nh * sizeof *across); /* triangle across edge k of t, or UINT32_MAX */
  unsigned char *flip = calloc(nt, 1), *seen = calloc(nt, 1);
  uint32_t *queue = malloc(nt * sizeof *queue);
  int rc = -1;
  if (!h || !across || !flip || !seen || !queue) goto done;
  for (size_t t = 0; t < nt; t++)
    for (int k = 0; k < 3; k++) {
      uint32_t a = m->tris[3 * t + k], b = m->tris[3 * t + (k + 1) % 3];
      uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
      h[3 * t + k] = (half_t){(uint64_t)lo << 32 | hi, (uint32_t)t};
      across[3 * t + k] = UINT32_MAX;
    }
  qsort(h, nh, sizeof *h, half_cmp);
  for (size_t i = 0; i + 1 < nh; i++) {
    if (h[i].key != h[i + 1].key) continue;
    uint32_t t0 = h[i].tri, t1 = h[i + 1].tri, lo = (uint32_t)(h[i].key >> 32), hi = (uint32_t)h[i].key;
    for (int k = 0; k < 3; k++) {
      uint32_t a = m->tris[3 * (size_t)t0 + k], b = m->tris[3 * (size_t)t0 + (k + 1) % 3];
      if ((a == lo && b == hi) || (a == hi && b == lo)) across[3 * (size_t)t0 + k] = t1;
      a = m->tris[3 * (size_t)t1 + k], b = m->tris[3 * (size_t)t1 + (k + 1) % 3];
      if ((a == lo && b == hi) || (a == hi && b == lo)) across[3 * (size_t)t1 + k] = t0;
    }
    i++;
  }
  rc = 0;
  for (size_t s = 0; s < nt && rc == 0; s++) {
    if (seen[s]) continue;
    size_t head = 0, tail = 0;
    queue[tail++] = (uint32_t)s;
    seen[s] = 1;
    while (head < tail && rc == 0) {
      uint32_t t = queue[head++];
      for (int k = 0; k < 3; k++) {
        uint32_t u = across[3 * (size_t)t + k];
        if (u == UINT32_MAX) continue;
        uint32_t a = m->tris[3 * (size_t)t + k], b = m->tris[3 * (size_t)t + (k + 1) % 3];
        if (flip[t]) { /* t runs b -> a */
          uint32_t c = a;
          a = b;
          b = c;
        }
        /* Agreeing neighbours run the shared edge the other way, b -> a. */
        int agrees = runs(m, flip, u, b, a);
        if (!seen[u]) {
          if (!agrees) flip[u] = 1;
          seen[u] = 1;
          queue[tail++] = u;
        } else if (!agrees) {
          rc = -2;
        }
      }
    }
  }
  if (rc == 0)
    for (size_t t = 0; t < nt; t++)
      if (flip[t]) {
        uint32_t c = m->tris[3 * t + 1];
        m->tris[3 * t + 1] = m->tris[3 * t + 2];
        m->tris[3 * t + 2] = c;
        (*flipped)++;
      }
done:
  free(h);
  free(across);
  free(flip);
  free(seen);
  free(queue);
  return rc;
}

/* Signed volume about the bounding-box centre (exact for a closed surface
 * wherever it lies, and without the round-off of far coordinates). */
static double volume_about(const mesh_t *m, const double c[3]) {
  double v = 0;
  for (size_t t = 0; t < m->ntris; t++) {
    double p[3][3], x[3];
    for (int k = 0; k < 3; k++) v3_sub(p[k], m->pos + 3 * (size_t)m->tris[3 * t + k], c);
    v3_cross(x, p[1], p[2]);
    v += v3_dot(p[0], x);
  }
  return v / 6.0;
}

static void flip_all(mesh_t *m) {
  for (size_t t = 0; t < m->ntris; t++) {
    uint32_t c = m->tris[3 * t + 1];
    m->tris[3 * t + 1] = m->tris[3 * t + 2];
    m->tris[3 * t + 2] = c;
  }
}

static void add_note(char *note, size_t size, const char *text) {
  size_t len = strlen(note);
  if (len < size) snprintf(note + len, size - len, "%s%s", len ? "; " : "", text);
}

int mesh_admit(mesh_t *m, const mesh_admit_opts_t *o, const char *what, char *note, size_t note_size, verr_t *err) {
  if (note_size) note[0] = '\0';
  if (mesh_validate(m, what, err)) return -1;
  if (m->nverts > UINT32_MAX) return verr_set(err, "%s: %zu vertices (at most %u)", what, m->nverts, UINT32_MAX);
  double bmin[3], bmax[3], c[3], d[3];
  mesh_bounds(m, bmin, bmax);
  v3_sub(d, bmax, bmin);
  double diag = v3_norm(d);
  if (!(diag >= o->min_size && diag <= o->max_size))
    return verr_set(err,
                    "%s: the mesh is %g m across (bounding-box diagonal, after scale), outside %g .. %g m for an "
                    "organ%s",
                    what, diag, o->min_size, o->max_size,
                    diag > o->max_size && diag / 1000 <= o->max_size ? " (a file in millimetres needs scale: 0.001)"
                                                                     : "");
  mesh_report_t r;
  if (mesh_check(m, &r)) return verr_set(err, "%s: out of memory checking the mesh", what);
  if (r.degenerate_faces)
    return verr_set(err, "%s: %zu degenerate triangle(s) (zero area or a repeated vertex): remove them", what,
                    r.degenerate_faces);
  if (r.nonmanifold_edges)
    return verr_set(err, "%s: non-manifold: %zu edge(s) shared by more than two triangles", what, r.nonmanifold_edges);
  if (r.components > 1)
    return verr_set(err,
                    "%s: the mesh is in %zu separate parts; one organ is one connected surface (give each part "
                    "its own organ)",
                    what, r.components);
  if (r.boundary_edges && !o->allow_open)
    return verr_set(err, "%s: open surface (%zu boundary edge(s)): this model needs a closed surface", what,
                    r.boundary_edges);
  char text[160];
  if (r.inconsistent_edges) {
    size_t flipped = 0;
    int rc = orient(m, &flipped);
    if (rc == -1) return verr_set(err, "%s: out of memory orienting the mesh", what);
    if (rc == -2) return verr_set(err, "%s: the surface cannot be oriented (a Moebius-like part)", what);
    snprintf(text, sizeof text, "%zu of %zu triangles re-wound to agree with their neighbours", flipped, m->ntris);
    add_note(note, note_size, text);
  }
  if (!r.boundary_edges) {
    for (int k = 0; k < 3; k++) c[k] = 0.5 * (bmin[k] + bmax[k]);
    double vol = volume_about(m, c);
    /* A closed surface encloses something: a volume below 1e-9 of its box is
     * a flattened (double-walled) sheet. */
    if (!(fabs(vol) > 1e-9 * diag * diag * diag))
      return verr_set(err, "%s: the closed surface encloses no volume (%g m^3)", what, vol);
    if (vol < 0) {
      flip_all(m);
      snprintf(text, sizeof text, "inside out (volume %.3g m^3): turned outward", vol);
      add_note(note, note_size, text);
    }
  }
  return 0;
}
