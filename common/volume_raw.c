/* SPDX-License-Identifier: Apache-2.0 */
/* volume_raw: the node and tetrahedron lists the format readers fill
 * (volume_raw.h), grown geometrically and bounded by VOLUME_MAX_TETS. */
#include "volume_raw.h"

#include <stdlib.h>
#include <string.h>

#include "volume_mesh.h"

static int grow(void **p, size_t *cap, size_t need, size_t elem, verr_t *err) {
  if (need <= *cap) return 0;
  size_t nc = *cap ? *cap : 1024;
  while (nc < need) nc *= 2;
  void *np = realloc(*p, nc * elem);
  if (!np) return verr_set(err, "out of memory for %zu entries", need);
  *p = np;
  *cap = nc;
  return 0;
}

int volume_raw_add_node(volume_raw_t *r, long long tag, const double p[3], verr_t *err) {
  size_t cap_tag = r->node_cap, cap_x = r->node_cap;
  if (grow((void **)&r->tag, &cap_tag, r->nnodes + 1, sizeof *r->tag, err) ||
      grow((void **)&r->x, &cap_x, r->nnodes + 1, 3 * sizeof *r->x, err))
    return -1;
  r->node_cap = cap_tag < cap_x ? cap_tag : cap_x;
  r->tag[r->nnodes] = tag;
  memcpy(r->x + 3 * r->nnodes, p, 3 * sizeof *p);
  r->nnodes++;
  return 0;
}

int volume_raw_add_tet(volume_raw_t *r, const long long c[4], int line, verr_t *err) {
  if (r->ntets >= VOLUME_MAX_TETS)
    return verr_set(err, "more than %d tetrahedra (line %d): too many to simulate at 1 kHz", VOLUME_MAX_TETS, line);
  size_t cap_c = r->tet_cap, cap_l = r->tet_cap;
  if (grow((void **)&r->corner, &cap_c, r->ntets + 1, 4 * sizeof *r->corner, err) ||
      grow((void **)&r->line, &cap_l, r->ntets + 1, sizeof *r->line, err))
    return -1;
  r->tet_cap = cap_c < cap_l ? cap_c : cap_l;
  memcpy(r->corner + 4 * r->ntets, c, 4 * sizeof *c);
  r->line[r->ntets++] = line;
  return 0;
}

void volume_raw_free(volume_raw_t *r) {
  free(r->tag);
  free(r->x);
  free(r->corner);
  free(r->line);
  memset(r, 0, sizeof *r);
}
