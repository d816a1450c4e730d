/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/ms_regions.h"

#include <stdlib.h>
#include <string.h>

static void set_bit(uint64_t *b, size_t k) { b[k >> 6] |= (uint64_t)1 << (k & 63); }
static void clear_bit(uint64_t *b, size_t k) { b[k >> 6] &= ~((uint64_t)1 << (k & 63)); }

void ms_regions_init(ms_regions_t *r, double force_wake, double speed_sleep, uint32_t need) {
  memset(r, 0, sizeof *r);
  r->force_wake = force_wake;
  r->speed_sleep = speed_sleep;
  r->need = need < 2 ? 2 : need; /* a node touched every sub-step never counts 2 still ones */
}

static void free_arrays(ms_regions_t *r) {
  free(r->adj_off);
  free(r->adj);
  free(r->awake);
  free(r->still);
  free(r->nbr_awake);
  free(r->blk_cnt);
  free(r->blk_bits);
  free(r->act_bits);
  free(r->list);
  free(r->f);
  r->adj_off = r->adj = r->still = r->nbr_awake = r->list = NULL;
  r->awake = r->blk_cnt = NULL;
  r->blk_bits = r->act_bits = NULL;
  r->f = NULL;
  r->springs = NULL;
  r->n = r->nsprings = r->nawake = 0;
}

void ms_regions_free(ms_regions_t *r) {
  free_arrays(r);
  memset(r, 0, sizeof *r);
}

int ms_regions_current(const ms_regions_t *r, const mass_spring_t *ms) {
  return r->springs && r->springs == ms->springs && r->nsprings == ms->nsprings && r->n == ms->n;
}

static void wake_node(ms_regions_t *r, size_t k) {
  r->awake[k] = 1;
  r->nawake++;
  r->wakes++;
  set_bit(r->act_bits, k);
  const ms_spring_t *sp = r->springs;
  for (uint32_t a = r->adj_off[k]; a < r->adj_off[k + 1]; a++) {
    const uint32_t s = r->adj[a], j = sp[s].i == k ? sp[s].j : sp[s].i;
    if (r->blk_cnt[s >> 2]++ == 0) set_bit(r->blk_bits, s >> 2);
    if (r->nbr_awake[j]++ == 0) set_bit(r->act_bits, j);
  }
}

static void sleep_node(ms_regions_t *r, double *v, size_t k) {
  r->awake[k] = 0;
  r->nawake--;
  r->sleeps++;
  r->still[k] = 0;
  v[3 * k] = v[3 * k + 1] = v[3 * k + 2] = 0;
  const ms_spring_t *sp = r->springs;
  for (uint32_t a = r->adj_off[k]; a < r->adj_off[k + 1]; a++) {
    const uint32_t s = r->adj[a], j = sp[s].i == k ? sp[s].j : sp[s].i;
    if (--r->blk_cnt[s >> 2] == 0) clear_bit(r->blk_bits, s >> 2);
    if (--r->nbr_awake[j] == 0 && !r->awake[j]) clear_bit(r->act_bits, j);
  }
  if (r->nbr_awake[k] == 0) clear_bit(r->act_bits, k);
}

int ms_regions_build(ms_regions_t *r, const mass_spring_t *ms, verr_t *err) {
  const size_t n = ms->n, ns = ms->nsprings, nb = (ns + 3) / 4;
  if (n >= UINT32_MAX || ns >= UINT32_MAX) return verr_set(err, "regions: %zu nodes, %zu springs is too many", n, ns);
  if (n > r->cap || ns > r->scap || !r->adj_off) {
    free_arrays(r);
    r->adj_off = malloc((n + 2) * sizeof *r->adj_off);
    r->adj = malloc((2 * ns + 1) * sizeof *r->adj);
    r->awake = malloc(n + 1);
    r->still = malloc((n + 1) * sizeof *r->still);
    r->nbr_awake = malloc((n + 1) * sizeof *r->nbr_awake);
    r->blk_cnt = malloc(nb + 1);
    r->blk_bits = malloc(((nb + 63) / 64 + 1) * sizeof *r->blk_bits);
    r->act_bits = malloc(((n + 63) / 64 + 1) * sizeof *r->act_bits);
    r->list = malloc((n + 1) * sizeof *r->list);
    r->f = malloc((3 * n + 1) * sizeof *r->f);
    if (!r->adj_off || !r->adj || !r->awake || !r->still || !r->nbr_awake || !r->blk_cnt || !r->blk_bits ||
        !r->act_bits || !r->list || !r->f) {
      free_arrays(r);
      r->cap = r->scap = 0;
      return verr_set(err, "regions: out of memory for %zu nodes", n);
    }
    r->cap = n;
    r->scap = ns;
  }
  const ms_spring_t *sp = ms->springs;
  /* Node -> springs, in spring order per node. */
  memset(r->adj_off, 0, (n + 2) * sizeof *r->adj_off);
  for (size_t s = 0; s < ns; s++) {
    r->adj_off[sp[s].i + 2]++;
    r->adj_off[sp[s].j + 2]++;
  }
  for (size_t k = 2; k < n + 2; k++) r->adj_off[k] += r->adj_off[k - 1];
  for (size_t s = 0; s < ns; s++) {
    r->adj[r->adj_off[sp[s].i + 1]++] = (uint32_t)s;
    r->adj[r->adj_off[sp[s].j + 1]++] = (uint32_t)s;
  }
  r->springs = sp;
  r->n = n;
  r->nsprings = ns;
  r->nawake = 0;
  r->builds++;
  memset(r->awake, 0, n);
  memset(r->still, 0, n * sizeof *r->still);
  memset(r->nbr_awake, 0, n * sizeof *r->nbr_awake);
  memset(r->blk_cnt, 0, nb);
  /* Every row and node once, so a row never evaluated later (springs
   * between fixed nodes) holds a value, not garbage. */
  memset(r->blk_bits, 0xff, ((nb + 63) / 64) * sizeof *r->blk_bits);
  memset(r->act_bits, 0xff, ((n + 63) / 64) * sizeof *r->act_bits);
  mass_spring_forces_subset(ms, ms->x, ms->v, r->f, r->blk_bits, r->act_bits);
  memset(r->blk_bits, 0, ((nb + 63) / 64) * sizeof *r->blk_bits);
  memset(r->act_bits, 0, ((n + 63) / 64) * sizeof *r->act_bits);
  for (size_t k = 0; k < n; k++)
    if (ms->inv_mass[k] != 0) wake_node(r, k);
  r->wakes -= r->nawake; /* a build is not a wake event */
  return 0;
}

void ms_regions_touch(ms_regions_t *r, const mass_spring_t *ms, uint32_t i) {
  if (i >= r->n || ms->inv_mass[i] == 0) return;
  r->still[i] = 0;
  if (!r->awake[i]) wake_node(r, i);
}

void ms_regions_wake_all(ms_regions_t *r, const mass_spring_t *ms) {
  for (size_t k = 0; k < r->n; k++) {
    r->still[k] = 0;
    if (!r->awake[k] && ms->inv_mass[k] != 0) wake_node(r, k);
  }
}

void ms_regions_substep(ms_regions_t *r, mass_spring_t *ms, double h) {
  double *restrict x = ms->x, *restrict v = ms->v, *restrict f = r->f;
  const double *restrict im = ms->inv_mass;
  r->substeps++;
  for (size_t w = 0; w < ((r->nsprings + 3) / 4 + 63) / 64; w++)
    r->block_evals += (uint64_t)__builtin_popcountll(r->blk_bits[w]);
  mass_spring_forces_subset(ms, x, v, f, r->blk_bits, r->act_bits);
  /* Kick: the awake nodes, and the frontier nodes whose force wakes them
   * (NaN wakes too, so the step's guard sees it). */
  const double fw2 = r->force_wake * r->force_wake;
  size_t nl = 0;
  for (size_t w = 0; w < (r->n + 63) / 64; w++)
    for (uint64_t bits = r->act_bits[w]; bits; bits &= bits - 1) {
      const size_t k = 64 * w + (size_t)__builtin_ctzll(bits);
      const double *fk = f + 3 * k;
      if (!r->awake[k]) {
        if (im[k] == 0 || fk[0] * fk[0] + fk[1] * fk[1] + fk[2] * fk[2] <= fw2) continue;
        r->still[k] = 0;
      }
      r->list[nl++] = (uint32_t)k;
      const double hw = h * im[k];
      v[3 * k] += hw * fk[0];
      v[3 * k + 1] += hw * fk[1];
      v[3 * k + 2] += hw * fk[2];
    }
  if (ms->fs.correct_v) ms->fs.correct_v(&ms->fs, h); /* its nodes were touched: awake */
  /* Drift, and the evidence of stillness. */
  const double fs2 = 0.25 * fw2, vs2 = r->speed_sleep * r->speed_sleep;
  for (size_t a = 0; a < nl; a++) {
    const size_t k = r->list[a];
    double *xk = x + 3 * k, *vk = v + 3 * k;
    const double *fk = f + 3 * k;
    xk[0] += h * vk[0];
    xk[1] += h * vk[1];
    xk[2] += h * vk[2];
    const int quiet =
        vk[0] * vk[0] + vk[1] * vk[1] + vk[2] * vk[2] < vs2 && fk[0] * fk[0] + fk[1] * fk[1] + fk[2] * fk[2] < fs2;
    r->still[k] = quiet ? r->still[k] + 1 : 0;
  }
  r->node_updates += nl;
  /* The decisions, after the sub-step (the sets above were fixed for it). */
  for (size_t a = 0; a < nl; a++) {
    const size_t k = r->list[a];
    if (!r->awake[k])
      wake_node(r, k);
    else if (r->still[k] >= r->need)
      sleep_node(r, v, k);
  }
}
