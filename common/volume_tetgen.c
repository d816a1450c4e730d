/* SPDX-License-Identifier: Apache-2.0 */
/* TetGen .node/.ele reader: see volume_mesh.h. Corners name nodes by the
 * index the .node file gives them, so files numbered from 0 and from 1 are
 * both read as written. */
#include <stdio.h>

#include "volume_raw.h"

#define TETGEN_MAX_COUNT 20000000LL

static int read_nodes(text_scan_t *s, volume_raw_t *r, verr_t *err) {
  long long n, dim, nattr, nmark, tag, m;
  double p[3], a;
  if (text_scan_long(s, "number of points", 0, TETGEN_MAX_COUNT, &n, err) ||
      text_scan_long(s, "dimension", 3, 3, &dim, err) ||
      text_scan_long(s, "number of attributes", 0, 64, &nattr, err) ||
      text_scan_long(s, "boundary marker flag", 0, 1, &nmark, err))
    return -1;
  for (long long i = 0; i < n; i++) {
    char what[48];
    if (text_scan_long(s, "point index", INT64_MIN, INT64_MAX, &tag, err)) return -1;
    for (int k = 0; k < 3; k++) {
      snprintf(what, sizeof what, "point %lld %c", tag, "xyz"[k]);
      if (text_scan_double(s, what, p + k, err)) return -1;
    }
    for (long long k = 0; k < nattr; k++)
      if (text_scan_double(s, "point attribute", &a, err)) return -1;
    if (nmark && text_scan_long(s, "boundary marker", INT64_MIN, INT64_MAX, &m, err)) return -1;
    if (volume_raw_add_node(r, tag, p, err)) return -1;
  }
  return 0;
}

static int read_tets(text_scan_t *s, volume_raw_t *r, verr_t *err) {
  long long n, per, nattr, tag, c[4];
  double a;
  if (text_scan_long(s, "number of tetrahedra", 0, TETGEN_MAX_COUNT, &n, err) ||
      text_scan_long(s, "nodes per tetrahedron", 4, 10, &per, err) ||
      text_scan_long(s, "number of attributes", 0, 64, &nattr, err))
    return -1;
  if (per != 4)
    return text_scan_fail(s, err, "%lld nodes per tetrahedron: only linear (4-node) tetrahedra are simulated", per);
  for (long long i = 0; i < n; i++) {
    if (text_scan_long(s, "tetrahedron index", INT64_MIN, INT64_MAX, &tag, err)) return -1;
    int line = s->tok_line;
    for (int k = 0; k < 4; k++)
      if (text_scan_long(s, "tetrahedron corner", INT64_MIN, INT64_MAX, c + k, err)) return -1;
    for (long long k = 0; k < nattr; k++)
      if (text_scan_double(s, "tetrahedron attribute", &a, err)) return -1;
    if (volume_raw_add_tet(r, c, line, err)) return -1;
  }
  return 0;
}

int volume_read_tetgen(text_scan_t *node, text_scan_t *ele, volume_raw_t *r, verr_t *err) {
  return read_nodes(node, r, err) || read_tets(ele, r, err) ? -1 : 0;
}
