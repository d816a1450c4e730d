/* SPDX-License-Identifier: Apache-2.0 */
/* VTK legacy reader (ASCII, UNSTRUCTURED_GRID): see volume_mesh.h for what
 * is read, skipped and refused. POINTS, CELLS and CELL_TYPES may come in any
 * order; FIELD blocks are skipped; reading ends at POINT_DATA or CELL_DATA,
 * which describe values the simulator does not use. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "volume_raw.h"

#define VTK_MAX_COUNT 20000000LL

typedef struct cells {
  long long n;      /* cells */
  long long *start; /* n + 1: connectivity offsets */
  long long *conn;  /* start[n] node indices */
  int *line;        /* n: line of each cell's record */
  long long *type;  /* n, from CELL_TYPES */
  int *type_line;   /* n */
  int have_cells, have_types;
} cells_t;

static void cells_free(cells_t *c) {
  free(c->start);
  free(c->conn);
  free(c->line);
  free(c->type);
  free(c->type_line);
}

static int alloc_fail(const text_scan_t *s, verr_t *err) { return text_scan_fail(s, err, "out of memory"); }

static int read_points(text_scan_t *s, volume_raw_t *r, verr_t *err) {
  long long n;
  if (r->nnodes) return text_scan_fail(s, err, "a second POINTS block");
  if (text_scan_long(s, "number of points", 0, VTK_MAX_COUNT, &n, err) || text_scan_next(s, err)) return -1;
  if (strcmp(s->tok, "float") && strcmp(s->tok, "double"))
    return text_scan_fail(s, err, "POINTS of type '%s': only float or double", s->tok);
  for (long long i = 0; i < n; i++) {
    double p[3];
    char what[48];
    for (int k = 0; k < 3; k++) {
      snprintf(what, sizeof what, "point %lld %c", i, "xyz"[k]);
      if (text_scan_double(s, what, p + k, err)) return -1;
    }
    if (volume_raw_add_node(r, i, p, err)) return -1;
  }
  return 0;
}

/* Classic layout: "CELLS n size" then n records "k i1 .. ik" (size numbers
 * in all); 5.1: "CELLS n+1 m", "OFFSETS type" n+1 numbers, "CONNECTIVITY
 * type" m numbers. */
static int read_cells(text_scan_t *s, cells_t *c, verr_t *err) {
  long long a, b;
  if (c->have_cells++) return text_scan_fail(s, err, "a second CELLS block");
  if (text_scan_long(s, "CELLS count", 0, VTK_MAX_COUNT, &a, err) ||
      text_scan_long(s, "CELLS size", 0, 8 * VTK_MAX_COUNT, &b, err))
    return -1;
  size_t save_pos = s->pos;
  int save_line = s->line;
  if (text_scan_next(s, err) < 0) return -1;
  int modern = !strcmp(s->tok, "OFFSETS");
  if (!modern) {
    s->pos = save_pos;
    s->line = save_line;
  }
  long long n = modern ? a - 1 : a;
  if (n < 0) return text_scan_fail(s, err, "CELLS with OFFSETS needs at least one offset");
  if (c->have_types && n != c->n) return text_scan_fail(s, err, "CELLS lists %lld cells, CELL_TYPES %lld", n, c->n);
  c->n = n;
  c->start = malloc((size_t)(n + 1) * sizeof *c->start);
  c->line = malloc((size_t)(n + 1) * sizeof *c->line);
  c->conn = malloc((size_t)(b + 1) * sizeof *c->conn);
  if (!c->start || !c->line || !c->conn) return alloc_fail(s, err);
  if (modern) {
    if (text_scan_next(s, err)) return -1; /* the offsets' type */
    for (long long i = 0; i <= n; i++) {
      if (text_scan_long(s, "cell offset", 0, b, c->start + i, err)) return -1;
      if (i && c->start[i] < c->start[i - 1]) return text_scan_fail(s, err, "cell offsets must not decrease");
      if (i < n) c->line[i] = s->tok_line;
    }
    if (c->start[0] != 0 || c->start[n] != b)
      return text_scan_fail(s, err, "cell offsets must run from 0 to the connectivity size %lld", b);
    if (text_scan_expect(s, "CONNECTIVITY", err) || text_scan_next(s, err)) return -1;
    for (long long i = 0; i < b; i++)
      if (text_scan_long(s, "cell point index", 0, VTK_MAX_COUNT, c->conn + i, err)) return -1;
    return 0;
  }
  long long used = 0, consumed = 0;
  for (long long i = 0; i < n; i++) {
    long long k;
    if (text_scan_long(s, "cell point count", 1, 1000, &k, err)) return -1;
    c->line[i] = s->tok_line;
    consumed += 1 + k;
    if (consumed > b) return text_scan_fail(s, err, "cell %lld runs past the CELLS size %lld", i, b);
    c->start[i] = used;
    for (long long j = 0; j < k; j++)
      if (text_scan_long(s, "cell point index", 0, VTK_MAX_COUNT, c->conn + used + j, err)) return -1;
    used += k;
  }
  c->start[n] = used;
  if (consumed != b)
    return text_scan_fail(s, err, "CELLS size %lld does not match its records (%lld numbers)", b, consumed);
  return 0;
}

static int read_types(text_scan_t *s, cells_t *c, verr_t *err) {
  long long n;
  if (c->have_types++) return text_scan_fail(s, err, "a second CELL_TYPES block");
  if (text_scan_long(s, "CELL_TYPES count", 0, VTK_MAX_COUNT, &n, err)) return -1;
  if (c->have_cells && n != c->n) return text_scan_fail(s, err, "CELL_TYPES lists %lld cells, CELLS %lld", n, c->n);
  c->type = malloc((size_t)(n + 1) * sizeof *c->type);
  c->type_line = malloc((size_t)(n + 1) * sizeof *c->type_line);
  if (!c->type || !c->type_line) return alloc_fail(s, err);
  for (long long i = 0; i < n; i++) {
    if (text_scan_long(s, "cell type", 0, 100, c->type + i, err)) return -1;
    c->type_line[i] = s->tok_line;
  }
  if (!c->have_cells) c->n = n;
  return 0;
}

/* FIELD name n, then n arrays "name components tuples type" and values. */
static int skip_field(text_scan_t *s, verr_t *err) {
  long long n, comp, tuples;
  if (text_scan_next(s, err) || text_scan_long(s, "FIELD array count", 0, 1000, &n, err)) return -1;
  for (long long a = 0; a < n; a++) {
    if (text_scan_next(s, err) || text_scan_long(s, "FIELD components", 0, 1000, &comp, err) ||
        text_scan_long(s, "FIELD tuples", 0, VTK_MAX_COUNT, &tuples, err) || text_scan_next(s, err))
      return -1;
    for (long long i = 0; i < comp * tuples; i++) {
      int rc = text_scan_next(s, err);
      if (rc) return rc < 0 ? -1 : text_scan_fail(s, err, "the file ends inside a FIELD array");
    }
  }
  return 0;
}

/* Cell types: 10 tetrahedron kept; 1-9 (vertices, lines, polygons) skipped. */
static int take_cells(const text_scan_t *s, const cells_t *c, volume_raw_t *r, verr_t *err) {
  for (long long i = 0; i < c->n; i++) {
    long long k = c->start[i + 1] - c->start[i], t = c->type[i];
    if (t == 10) {
      if (k != 4)
        return verr_set(err, "%s:%d: cell %lld is a tetrahedron (type 10) with %lld points", s->path, c->line[i], i, k);
      if (volume_raw_add_tet(r, c->conn + c->start[i], c->line[i], err)) return -1;
    } else if (t >= 1 && t <= 9) {
      r->skipped++;
    } else {
      return verr_set(err, "%s:%d: cell %lld has VTK type %lld (%s): only tetrahedra (type 10) are simulated", s->path,
                      c->type_line[i], i, t,
                      t == 12   ? "hexahedron"
                      : t == 13 ? "wedge"
                      : t == 14 ? "pyramid"
                      : t == 24 ? "quadratic tetrahedron"
                                : "not a linear tetrahedron");
    }
  }
  return 0;
}

int volume_read_vtk(text_scan_t *s, volume_raw_t *r, verr_t *err) {
  static const char magic[] = "# vtk DataFile Version";
  if (s->len < sizeof magic - 1 || memcmp(s->buf, magic, sizeof magic - 1))
    return verr_set(err, "%s:1: not a VTK legacy file (it must start with '%s')", s->path, magic);
  text_scan_next_line(s); /* version */
  text_scan_next_line(s); /* title: free text */
  if (text_scan_next(s, err)) return text_scan_fail(s, err, "the file ends before ASCII/BINARY");
  if (strcmp(s->tok, "ASCII")) return text_scan_fail(s, err, "'%s': only ASCII VTK files are read", s->tok);
  if (text_scan_expect(s, "DATASET", err) || text_scan_next(s, err)) return -1;
  if (strcmp(s->tok, "UNSTRUCTURED_GRID"))
    return text_scan_fail(s, err, "DATASET %s: only UNSTRUCTURED_GRID holds tetrahedra", s->tok);
  cells_t c;
  memset(&c, 0, sizeof c);
  int rc = 0;
  for (;;) {
    int t = text_scan_next(s, err);
    if (t < 0) rc = -1;
    if (t) break;
    if (!strcmp(s->tok, "POINTS"))
      rc = read_points(s, r, err);
    else if (!strcmp(s->tok, "CELLS"))
      rc = read_cells(s, &c, err);
    else if (!strcmp(s->tok, "CELL_TYPES"))
      rc = read_types(s, &c, err);
    else if (!strcmp(s->tok, "FIELD"))
      rc = skip_field(s, err);
    else if (!strcmp(s->tok, "POINT_DATA") || !strcmp(s->tok, "CELL_DATA") || !strcmp(s->tok, "METADATA"))
      break;
    else
      rc = text_scan_fail(s, err, "unexpected '%s' (POINTS, CELLS, CELL_TYPES or FIELD expected)", s->tok);
    if (rc) break;
  }
  if (!rc && (!c.have_cells || !c.have_types))
    rc = verr_set(err, "%s: %s", s->path, !c.have_cells ? "no CELLS block" : "no CELL_TYPES block");
  if (!rc && c.have_cells && c.type && c.n > 0 && c.type_line) rc = take_cells(s, &c, r, err);
  cells_free(&c);
  return rc;
}
