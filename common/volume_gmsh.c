/* SPDX-License-Identifier: Apache-2.0 */
/* gmsh MSH reader (ASCII 2.2, 4.0 and 4.1): see volume_mesh.h for what is
 * read, skipped and refused. Only $MeshFormat, $Nodes and $Elements matter;
 * every other section ($PhysicalNames, $Entities, $NodeData, ...) is skipped
 * to its $End line. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "volume_raw.h"

#define MSH_MAX_COUNT 20000000LL /* nodes or elements in one file */

/* Corners of the element types a volume file holds besides tetrahedra:
 * lower-dimensional ones are skipped (0 for the types that are refused). */
static int skipped_corners(long long type) {
  switch (type) {
  case 1:
    return 2; /* line */
  case 2:
    return 3; /* triangle */
  case 3:
    return 4; /* quadrangle */
  case 8:
    return 3; /* 3-node line */
  case 9:
    return 6; /* 6-node triangle */
  case 10:
    return 9; /* 9-node quadrangle */
  case 15:
    return 1; /* point */
  default:
    return 0;
  }
}

static const char *refused_name(long long type) {
  switch (type) {
  case 5:
    return "hexahedron";
  case 6:
    return "prism";
  case 7:
    return "pyramid";
  case 11:
    return "10-node tetrahedron";
  case 17:
    return "20-node hexahedron";
  default:
    return "element";
  }
}

static int read_xyz(text_scan_t *s, long long tag, double p[3], verr_t *err) {
  char what[64];
  for (int k = 0; k < 3; k++) {
    snprintf(what, sizeof what, "node %lld %c", tag, "xyz"[k]);
    if (text_scan_double(s, what, p + k, err)) return -1;
  }
  return 0;
}

/* One element of `type` whose corners follow: a tetrahedron is kept, a
 * lower-dimensional one skipped, anything else refused. */
static int element(text_scan_t *s, volume_raw_t *r, long long tag, long long type, verr_t *err) {
  int line = s->tok_line;
  if (type == 4) {
    long long c[4];
    for (int k = 0; k < 4; k++)
      if (text_scan_long(s, "tetrahedron corner", 0, INT64_MAX, c + k, err)) return -1;
    return volume_raw_add_tet(r, c, line, err);
  }
  int n = skipped_corners(type);
  if (!n)
    return text_scan_fail(s, err,
                          "element %lld is a %s (gmsh type %lld): only 4-node tetrahedra (type 4) are simulated", tag,
                          refused_name(type), type);
  for (int k = 0; k < n; k++) {
    long long v;
    if (text_scan_long(s, "element corner", 0, INT64_MAX, &v, err)) return -1;
  }
  r->skipped++;
  return 0;
}

static int nodes_v2(text_scan_t *s, volume_raw_t *r, verr_t *err) {
  long long n, tag;
  double p[3];
  if (text_scan_long(s, "number of nodes", 0, MSH_MAX_COUNT, &n, err)) return -1;
  for (long long i = 0; i < n; i++) {
    if (text_scan_long(s, "node tag", 0, INT64_MAX, &tag, err) || read_xyz(s, tag, p, err) ||
        volume_raw_add_node(r, tag, p, err))
      return -1;
  }
  return text_scan_expect(s, "$EndNodes", err);
}

static int elements_v2(text_scan_t *s, volume_raw_t *r, verr_t *err) {
  long long n, tag, type, ntags, t;
  if (text_scan_long(s, "number of elements", 0, MSH_MAX_COUNT, &n, err)) return -1;
  for (long long i = 0; i < n; i++) {
    if (text_scan_long(s, "element tag", 0, INT64_MAX, &tag, err) ||
        text_scan_long(s, "element type", 0, 1000, &type, err) ||
        text_scan_long(s, "number of element tags", 0, 64, &ntags, err))
      return -1;
    for (long long k = 0; k < ntags; k++)
      if (text_scan_long(s, "element tag value", INT64_MIN, INT64_MAX, &t, err)) return -1;
    if (element(s, r, tag, type, err)) return -1;
  }
  return text_scan_expect(s, "$EndElements", err);
}

/* A 4.x section's header: "blocks count" and, in 4.1, "min_tag max_tag";
 * `what` names the section's items ("node", "element"). */
static int section_v4(text_scan_t *s, int v41, const char *what, long long *nblocks, long long *n, verr_t *err) {
  char a[48], b[48];
  long long tag;
  snprintf(a, sizeof a, "number of %s blocks", what);
  snprintf(b, sizeof b, "number of %ss", what);
  if (text_scan_long(s, a, 0, MSH_MAX_COUNT, nblocks, err) || text_scan_long(s, b, 0, MSH_MAX_COUNT, n, err)) return -1;
  snprintf(a, sizeof a, "minimum %s tag", what);
  snprintf(b, sizeof b, "maximum %s tag", what);
  if (v41 && (text_scan_long(s, a, 0, INT64_MAX, &tag, err) || text_scan_long(s, b, 0, INT64_MAX, &tag, err)))
    return -1;
  return 0;
}

/* A block's first two numbers: "dim entity" in 4.1, "entity dim" in 4.0. */
static int block_dim_v4(text_scan_t *s, int v41, long long *dim, verr_t *err) {
  long long entity;
  if (v41)
    return text_scan_long(s, "block dimension", 0, 3, dim, err) ||
                   text_scan_long(s, "block entity", INT64_MIN, INT64_MAX, &entity, err)
               ? -1
               : 0;
  return text_scan_long(s, "block entity", INT64_MIN, INT64_MAX, &entity, err) ||
                 text_scan_long(s, "block dimension", 0, 3, dim, err)
             ? -1
             : 0;
}

/* 4.1 blocks start "dim entity parametric count", 4.0 ones "entity dim
 * parametric count"; 4.1 lists the block's tags first, then coordinates. */
static int nodes_v4(text_scan_t *s, volume_raw_t *r, int v41, verr_t *err) {
  long long nblocks, n, dim, parametric, count;
  if (section_v4(s, v41, "node", &nblocks, &n, err)) return -1;
  for (long long b = 0; b < nblocks; b++) {
    if (block_dim_v4(s, v41, &dim, err)) return -1;
    if (text_scan_long(s, "parametric flag", 0, 1, &parametric, err) ||
        text_scan_long(s, "nodes in block", 0, n, &count, err))
      return -1;
    size_t first = r->nnodes;
    double p[3] = {0, 0, 0}, u;
    for (long long i = 0; i < count; i++) {
      long long tag;
      if (text_scan_long(s, "node tag", 0, INT64_MAX, &tag, err)) return -1;
      if (v41) {
        if (volume_raw_add_node(r, tag, p, err)) return -1;
        continue;
      }
      if (read_xyz(s, tag, p, err) || volume_raw_add_node(r, tag, p, err)) return -1;
      for (long long k = 0; k < (parametric ? dim : 0); k++)
        if (text_scan_double(s, "parametric coordinate", &u, err)) return -1;
    }
    for (long long i = 0; v41 && i < count; i++) {
      double *x = r->x + 3 * (first + (size_t)i);
      if (read_xyz(s, r->tag[first + (size_t)i], x, err)) return -1;
      for (long long k = 0; k < (parametric ? dim : 0); k++)
        if (text_scan_double(s, "parametric coordinate", &u, err)) return -1;
    }
  }
  return text_scan_expect(s, "$EndNodes", err);
}

static int elements_v4(text_scan_t *s, volume_raw_t *r, int v41, verr_t *err) {
  long long nblocks, n, dim, type, count, tag;
  if (section_v4(s, v41, "element", &nblocks, &n, err)) return -1;
  for (long long b = 0; b < nblocks; b++) {
    if (block_dim_v4(s, v41, &dim, err)) return -1;
    if (text_scan_long(s, "element type", 0, 1000, &type, err) ||
        text_scan_long(s, "elements in block", 0, n, &count, err))
      return -1;
    for (long long i = 0; i < count; i++)
      if (text_scan_long(s, "element tag", 0, INT64_MAX, &tag, err) || element(s, r, tag, type, err)) return -1;
  }
  return text_scan_expect(s, "$EndElements", err);
}

static int skip_section(text_scan_t *s, const char *name, verr_t *err) {
  char end[TEXT_SCAN_TOKEN_MAX + 4];
  snprintf(end, sizeof end, "$End%s", name + 1);
  for (;;) {
    int rc = text_scan_next(s, err);
    if (rc < 0) return -1;
    if (rc > 0) return text_scan_fail(s, err, "section %s has no %s", name, end);
    if (!strcmp(s->tok, end)) return 0;
  }
}

int volume_read_msh(text_scan_t *s, volume_raw_t *r, verr_t *err) {
  double version;
  long long type, size;
  if (text_scan_expect(s, "$MeshFormat", err) || text_scan_double(s, "format version", &version, err)) return -1;
  int v2 = version >= 2.0 && version < 3.0, v40 = version == 4.0, v41 = version == 4.1;
  if (!v2 && !v40 && !v41) return text_scan_fail(s, err, "MSH version %g: only 2.x, 4.0 and 4.1 are read", version);
  if (text_scan_long(s, "file type", 0, 1, &type, err)) return -1;
  if (type == 1)
    return text_scan_fail(s, err, "binary MSH is not read: save the mesh as ASCII (gmsh -save_all -format msh4)");
  if (text_scan_long(s, "data size", 1, 16, &size, err) || text_scan_expect(s, "$EndMeshFormat", err)) return -1;
  int have_nodes = 0, have_elements = 0;
  for (;;) {
    int rc = text_scan_next(s, err);
    if (rc < 0) return -1;
    if (rc > 0) break;
    if (s->tok[0] != '$')
      return text_scan_fail(s, err, "expected a section ($Nodes, $Elements, ...), found '%s'", s->tok);
    if (!strcmp(s->tok, "$Nodes")) {
      if (have_nodes++) return text_scan_fail(s, err, "a second $Nodes section");
      if (v2 ? nodes_v2(s, r, err) : nodes_v4(s, r, v41, err)) return -1;
    } else if (!strcmp(s->tok, "$Elements")) {
      if (have_elements++) return text_scan_fail(s, err, "a second $Elements section");
      if (v2 ? elements_v2(s, r, err) : elements_v4(s, r, v41, err)) return -1;
    } else {
      char name[TEXT_SCAN_TOKEN_MAX];
      snprintf(name, sizeof name, "%s", s->tok);
      if (skip_section(s, name, err)) return -1;
    }
  }
  if (!have_nodes) return verr_set(err, "%s: no $Nodes section", s->path);
  if (!have_elements) return verr_set(err, "%s: no $Elements section", s->path);
  return 0;
}
