/* SPDX-License-Identifier: Apache-2.0 */
#include "cutting/tet_model_cut.h"

#include <stdlib.h>
#include <string.h>

#include "state_blob.h"

struct tet_model_cut {
  model_t *m;
  tet_cut_t *cut; /* NULL until prepared */
  int broken;     /* a commit failed: the model no longer matches the cutter */
};

tet_model_cut_t *tet_model_cut_create(model_t *m, verr_t *err) {
  if (!m || !m->ops->edit || m->ops->edit->kind != MODEL_EDIT_TETS) {
    verr_set(err, "cutting needs a pbd or xpbd model");
    return NULL;
  }
  tet_model_cut_t *c = calloc(1, sizeof *c);
  if (!c) verr_set(err, "out of memory for the cutter");
  if (c) c->m = m;
  return c;
}

void tet_model_cut_destroy(tet_model_cut_t *c) {
  if (!c) return;
  if (c->cut) tet_cut_destroy(c->cut);
  free(c->cut);
  free(c);
}

const tet_cut_t *tet_model_cut_mesh(const tet_model_cut_t *c) { return c ? c->cut : NULL; }

int tet_model_cut_prepare(tet_model_cut_t *c, verr_t *err) {
  if (c->cut) return 0;
  model_nodes_t nv;
  c->m->ops->edit->nodes(c->m, &nv);
  uint8_t *fixed = malloc(nv.n ? nv.n : 1);
  c->cut = calloc(1, sizeof *c->cut);
  if (!fixed || !c->cut) {
    free(fixed);
    free(c->cut);
    c->cut = NULL;
    return verr_set(err, "out of memory for the cutter");
  }
  for (size_t i = 0; i < nv.n; i++) fixed[i] = nv.inv_mass[i] == 0;
  int rc = tet_cut_create(c->cut, nv.n, nv.x_rest, nv.x, nv.v, fixed, nv.ntets, nv.tets, err);
  free(fixed);
  if (rc) {
    free(c->cut);
    c->cut = NULL;
    return -1;
  }
  return 0;
}

/* The cutter's mesh into the model (model.h edit->commit). */
static int commit(model_t *m, const tet_cut_t *tc, verr_t *err) {
  uint32_t *tris = NULL;
  size_t nt = tet_cut_boundary(tc, &tris);
  if (nt == (size_t)-1) {
    free(tris);
    return verr_set(err, "out of memory for the surface after a cut");
  }
  model_topology_t t = {.n = tc->n,
                        .x = tc->x,
                        .v = tc->v,
                        .x_rest = tc->x_rest,
                        .attr = tc->attr,
                        .fixed = tc->fixed,
                        .ntets = tc->ntets,
                        .tets = tc->tet,
                        .ntris = nt,
                        .tris = tris};
  int rc = m->ops->edit->commit(m, &t, err);
  free(tris);
  return rc;
}

/* One cutter call on the model's current state. */
static int cut_call(tet_model_cut_t *c, const double *tip, const double *handle, verr_t *err) {
  if (c->broken) return verr_set(err, "cutting disabled after a failed rebuild");
  if (!tip && !c->cut) return 0; /* nothing was cut: nothing to end */
  if (!c->cut && tet_model_cut_prepare(c, err)) return -1;
  tet_cut_t *tc = c->cut;
  /* The cutter holds the same nodes as the model (committed together). */
  memcpy(tc->x, c->m->x, 3 * tc->n * sizeof(double));
  memcpy(tc->v, c->m->v, 3 * tc->n * sizeof(double));
  uint32_t version = tc->version;
  int n = tip ? tet_cut_advance(tc, tip, handle, err) : tet_cut_end(tc, err);
  if (n < 0) return -1;
  if (tc->version != version && commit(c->m, tc, err)) {
    c->broken = 1;
    return -1;
  }
  return n;
}

int tet_model_cut_advance(tet_model_cut_t *c, const double tip[3], const double handle[3], verr_t *err) {
  if (!tip || !handle) return verr_set(err, "no blade");
  return cut_call(c, tip, handle, err);
}

int tet_model_cut_end(tet_model_cut_t *c, verr_t *err) { return cut_call(c, NULL, NULL, err); }

int tet_model_cut_save(const tet_model_cut_t *c, state_blob_t *b) {
  if (!c->cut || c->broken) return -1;
  tet_cut_save(c->cut, b);
  sb_put_u64(b, c->m->topology_version);
  return b->bad ? -1 : 0;
}

int tet_model_cut_restore(tet_model_cut_t *c, state_blob_t *b, size_t nnodes, const double *x, const double *v,
                          verr_t *err) {
  tet_cut_t *nc = calloc(1, sizeof *nc);
  if (!nc) return verr_set(err, "out of memory for the cutter");
  verr_t sub;
  if (tet_cut_load(nc, b, &sub)) {
    free(nc);
    return verr_set(err, "cut mesh: %s", sub.msg);
  }
  uint64_t version = sb_get_u64(b);
  if (b->bad || version == 0 || version > UINT32_MAX || nc->n != nnodes) {
    tet_cut_destroy(nc);
    free(nc);
    return verr_set(err, "cut mesh: bad topology version or node count");
  }
  /* The saved positions and velocities are the cutter's too. */
  memcpy(nc->x, x, 3 * nnodes * sizeof(double));
  memcpy(nc->v, v, 3 * nnodes * sizeof(double));
  if (commit(c->m, nc, err)) { /* the model is unchanged: the old cutter stays */
    tet_cut_destroy(nc);
    free(nc);
    return -1;
  }
  if (c->cut) tet_cut_destroy(c->cut);
  free(c->cut);
  c->cut = nc;
  c->broken = 0;
  c->m->topology_version = (uint32_t)version;
  return 0;
}
