/* SPDX-License-Identifier: Apache-2.0 */
/* coupling: the rank-one implicit solve of coupling.h, spring by spring. */
#include "physics/coupling.h"

#include <stdlib.h>
#include <string.h>

int coupling_set_init(coupling_set_t *cs, size_t cap, size_t ecap, verr_t *err) {
  memset(cs, 0, sizeof *cs);
  cs->s = malloc(cap * sizeof *cs->s + 1);
  cs->node = malloc(ecap * sizeof *cs->node + 1);
  cs->wt = malloc(ecap * sizeof *cs->wt + 1);
  if (!cs->s || !cs->node || !cs->wt) {
    coupling_set_free(cs);
    return verr_set(err, "coupling: out of memory");
  }
  cs->cap = cap;
  cs->ecap = ecap;
  return 0;
}

void coupling_set_free(coupling_set_t *cs) {
  free(cs->s);
  free(cs->node);
  free(cs->wt);
  memset(cs, 0, sizeof *cs);
}

void coupling_begin(coupling_set_t *cs, double k) {
  cs->open = 0;
  if (!cs->s || cs->n >= cs->cap || !(k > 0)) {
    if (cs->s && k > 0) cs->dropped++;
    return;
  }
  coupling_spring_t *sp = &cs->s[cs->n];
  sp->k = k;
  sp->w0 = sp->b0 = (uint32_t)cs->ne;
  sp->nw = sp->nb = 0;
  cs->open = 1;
}

static int push(coupling_set_t *cs, uint32_t node, double w) {
  if (!cs->open) return 0;
  if (cs->ne >= cs->ecap) { /* does not fit: the spring stays explicit */
    cs->open = 0;
    cs->ne = cs->s[cs->n].w0;
    cs->dropped++;
    return 0;
  }
  cs->node[cs->ne] = node;
  cs->wt[cs->ne] = w;
  cs->ne++;
  return 1;
}

void coupling_push_w(coupling_set_t *cs, uint32_t node, double w) {
  if (push(cs, node, w)) {
    cs->s[cs->n].nw++;
    cs->s[cs->n].b0 = (uint32_t)cs->ne;
  }
}

void coupling_push_b(coupling_set_t *cs, uint32_t node, double b) {
  if (push(cs, node, b)) cs->s[cs->n].nb++;
}

void coupling_end(coupling_set_t *cs) {
  if (!cs->open) return;
  cs->open = 0;
  const coupling_spring_t *sp = &cs->s[cs->n];
  if (sp->nw && sp->nb)
    cs->n++;
  else
    cs->ne = sp->w0; /* nothing to couple */
}

void coupling_add(coupling_set_t *cs, double k, size_t n, size_t nw, const uint32_t *wi, const double *w, size_t nb,
                  const uint32_t *bi, const double *b) {
  coupling_begin(cs, k);
  for (size_t j = 0; j < nw; j++)
    if (wi[j] < n) coupling_push_w(cs, wi[j], w[j]);
  for (size_t l = 0; l < nb; l++)
    if (bi[l] < n) coupling_push_b(cs, bi[l], b[l]);
  coupling_end(cs);
}

void coupling_set_apply(const coupling_set_t *cs, const double *inv_mass, double h, double *v) {
  for (size_t c = 0; c < cs->n; c++) {
    const coupling_spring_t *sp = &cs->s[c];
    const uint32_t *wn = cs->node + sp->w0, *bn = cs->node + sp->b0;
    const double *w = cs->wt + sp->w0, *b = cs->wt + sp->b0;
    double s[3] = {0, 0, 0}, q = 0;
    for (uint32_t l = 0; l < sp->nb; l++) {
      const double *vl = v + 3 * (size_t)bn[l];
      if (inv_mass[bn[l]] == 0) continue; /* a fixed node does not move */
      s[0] += b[l] * vl[0];
      s[1] += b[l] * vl[1];
      s[2] += b[l] * vl[2];
    }
    /* q = b^T M^-1 w over the nodes the two sets share. */
    for (uint32_t j = 0; j < sp->nw; j++) {
      double im = inv_mass[wn[j]];
      if (im == 0) continue;
      for (uint32_t l = 0; l < sp->nb; l++)
        if (bn[l] == wn[j]) q += b[l] * w[j] * im;
    }
    const double hk = h * h * sp->k, scale = hk / (1 + hk * q);
    for (uint32_t j = 0; j < sp->nw; j++) {
      double im = inv_mass[wn[j]];
      if (im == 0) continue;
      double *vj = v + 3 * (size_t)wn[j], a = scale * im * w[j];
      vj[0] -= a * s[0];
      vj[1] -= a * s[1];
      vj[2] -= a * s[2];
    }
  }
}

void coupling_set_drift(const coupling_set_t *cs, const double *inv_mass, double h, const double *x_old,
                        const double *v, double *x) {
  for (size_t c = 0; c < cs->n; c++) {
    const coupling_spring_t *sp = &cs->s[c];
    for (uint32_t j = 0; j < sp->nw; j++) {
      size_t o = 3 * (size_t)cs->node[sp->w0 + j];
      if (inv_mass[o / 3] == 0) continue;
      x[o] = x_old[o] + h * v[o];
      x[o + 1] = x_old[o + 1] + h * v[o + 1];
      x[o + 2] = x_old[o + 2] + h * v[o + 2];
    }
  }
}
