/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/ms_regions.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void set_bit(uint64_t *b, size_t k) { b[k >> 6] |= (uint64_t)1 << (k & 63); }
static void clear_bit(uint64_t *b, size_t k) { b[k >> 6] &= ~((uint64_t)1 << (k & 63)); }
static size_t words(size_t bits) { return (bits + 63) / 64; }

void ms_regions_init(ms_regions_t *r, double force_wake, double speed_sleep) {
  memset(r, 0, sizeof *r);
  r->force_wake = force_wake;
  r->speed_sleep = speed_sleep;
}

static void free_arrays(ms_regions_t *r) {
  free(r->adj_off);
  free(r->adj);
  free(r->awake);
  free(r->held);
  free(r->touched);
  free(r->nbr_held);
  free(r->blk_cnt);
  free(r->blk_bits);
  free(r->act_bits);
  free(r->list);
  free(r->pend);
  free(r->pend2);
  free(r->f);
  free(r->xs);
  free(r->gx);
  free(r->gidx);
  free(r->saved);
  r->xs = r->gx = r->gv = NULL;
  r->gidx = NULL;
  r->saved = NULL;
  r->in_step = 0;
  r->gn = 0;
  r->adj_off = r->adj = r->nbr_held = r->list = r->pend = r->pend2 = NULL;
  r->awake = r->held = r->touched = r->blk_cnt = NULL;
  r->blk_bits = r->act_bits = NULL;
  r->f = NULL;
  r->springs = NULL;
  r->n = r->nsprings = r->nawake = r->npend = r->cap = r->scap = 0;
}

void ms_regions_free(ms_regions_t *r) {
  free_arrays(r);
  memset(r, 0, sizeof *r);
}

int ms_regions_current(const ms_regions_t *r, const mass_spring_t *ms) {
  return r->springs && r->springs == ms->springs && r->nsprings == ms->nsprings && r->n == ms->n;
}

/* The step's guard keeps node k's state from before the step (once). */
static void guard_save(ms_regions_t *r, size_t k) {
  if (!r->in_step || r->saved[k]) return;
  r->saved[k] = 1;
  r->gidx[r->gn] = (uint32_t)k;
  memcpy(r->gx + 3 * r->gn, r->sx + 3 * k, 3 * sizeof(double));
  memcpy(r->gv + 3 * r->gn, r->sv + 3 * k, 3 * sizeof(double));
  r->gn++;
}

/* Counts node k as held: its springs' blocks are evaluated, its
 * neighbours' forces too. */
static void hold(ms_regions_t *r, size_t k) {
  r->held[k] = 1;
  set_bit(r->act_bits, k);
  const ms_spring_t *sp = r->springs;
  for (uint32_t a = r->adj_off[k]; a < r->adj_off[k + 1]; a++) {
    const uint32_t s = r->adj[a], j = sp[s].i == k ? sp[s].j : sp[s].i;
    if (r->blk_cnt[s >> 2]++ == 0) set_bit(r->blk_bits, s >> 2);
    if (r->nbr_held[j]++ == 0) set_bit(r->act_bits, j);
  }
}

static void release(ms_regions_t *r, size_t k) {
  r->held[k] = 0;
  const ms_spring_t *sp = r->springs;
  for (uint32_t a = r->adj_off[k]; a < r->adj_off[k + 1]; a++) {
    const uint32_t s = r->adj[a], j = sp[s].i == k ? sp[s].j : sp[s].i;
    if (--r->blk_cnt[s >> 2] == 0) clear_bit(r->blk_bits, s >> 2);
    if (--r->nbr_held[j] == 0 && !r->held[j]) clear_bit(r->act_bits, j);
  }
  if (r->nbr_held[k] == 0) clear_bit(r->act_bits, k);
}

static void wake(ms_regions_t *r, size_t k) {
  guard_save(r, k); /* asleep until now: its state is the one from before the step */
  r->awake[k] = 1;
  r->nawake++;
  r->wakes++;
  if (!r->held[k]) hold(r, k); /* a node that fell asleep in the last sub-step is still held */
}

static int reserve(ms_regions_t *r, size_t n, size_t ns) {
  if (n <= r->cap && ns <= r->scap && r->adj_off) return 0;
  free_arrays(r);
  const size_t nb = (ns + 3) / 4;
  r->adj_off = malloc((n + 2) * sizeof *r->adj_off);
  r->adj = malloc((2 * ns + 1) * sizeof *r->adj);
  r->awake = malloc(n + 1);
  r->held = malloc(n + 1);
  r->touched = malloc(n + 1);
  r->nbr_held = malloc((n + 1) * sizeof *r->nbr_held);
  r->blk_cnt = malloc(nb + 1);
  r->blk_bits = malloc((words(nb) + 1) * sizeof *r->blk_bits);
  r->act_bits = malloc((words(n) + 1) * sizeof *r->act_bits);
  r->list = malloc((n + 1) * sizeof *r->list);
  r->pend = malloc((n + 1) * sizeof *r->pend);
  r->pend2 = malloc((n + 1) * sizeof *r->pend2);
  r->f = malloc((3 * n + 1) * sizeof *r->f);
  r->xs = malloc((3 * n + 1) * sizeof *r->xs);
  r->gx = malloc((6 * n + 1) * sizeof *r->gx);
  r->gv = r->gx ? r->gx + 3 * n : NULL;
  r->gidx = malloc((n + 1) * sizeof *r->gidx);
  r->saved = malloc(n + 1);
  if (!r->adj_off || !r->adj || !r->awake || !r->held || !r->touched || !r->nbr_held || !r->blk_cnt || !r->blk_bits ||
      !r->act_bits || !r->list || !r->pend || !r->pend2 || !r->f || !r->xs || !r->gx || !r->gidx || !r->saved) {
    free_arrays(r);
    return -1;
  }
  r->cap = n;
  r->scap = ns;
  return 0;
}

int ms_regions_build(ms_regions_t *r, const mass_spring_t *ms, verr_t *err) {
  const size_t n = ms->n, ns = ms->nsprings, nb = (ns + 3) / 4;
  r->springs = NULL;
  if (n >= UINT32_MAX / 2 || ns >= UINT32_MAX / 2)
    return verr_set(err, "regions: %zu nodes, %zu springs is too many", n, ns);
  if (reserve(r, n, ns)) return verr_set(err, "regions: out of memory for %zu nodes", n);
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
  r->nawake = r->npend = 0;
  r->builds++;
  memset(r->awake, 0, n);
  memset(r->held, 0, n);
  memset(r->touched, 0, n);
  memset(r->saved, 0, n);
  r->in_step = 0;
  r->gn = 0;
  memset(r->nbr_held, 0, n * sizeof *r->nbr_held);
  memset(r->blk_cnt, 0, nb);
  /* Every row and every node's force once: the rows of springs that stay
   * asleep are then those of the current positions. */
  memset(r->blk_bits, 0xff, words(nb) * sizeof *r->blk_bits);
  memset(r->act_bits, 0xff, words(n) * sizeof *r->act_bits);
  mass_spring_forces_subset(ms, ms->x, ms->v, r->f, r->blk_bits, r->act_bits);
  memset(r->blk_bits, 0, words(nb) * sizeof *r->blk_bits);
  memset(r->act_bits, 0, words(n) * sizeof *r->act_bits);
  /* Asleep: free nodes at rest with at most force_wake (the file comment). */
  const double fw2 = r->force_wake * r->force_wake, *v = ms->v, *f = r->f;
  memcpy(r->xs, ms->x, 3 * n * sizeof *r->xs);
  for (size_t k = 0; k < n; k++) {
    if (ms->inv_mass[k] == 0) continue;
    const double *fk = f + 3 * k, *vk = v + 3 * k;
    if (vk[0] != 0 || vk[1] != 0 || vk[2] != 0 || !(fk[0] * fk[0] + fk[1] * fk[1] + fk[2] * fk[2] <= fw2)) {
      r->awake[k] = 1;
      r->nawake++;
      hold(r, k);
    }
  }
  return 0;
}

void ms_regions_touch(ms_regions_t *r, const mass_spring_t *ms, uint32_t i) {
  if (i >= r->n || ms->inv_mass[i] == 0) return;
  r->touched[i] = 1;
  if (!r->awake[i]) wake(r, i);
}

void ms_regions_substep(ms_regions_t *r, mass_spring_t *ms, double h) {
  double *restrict x = ms->x, *restrict v = ms->v, *restrict f = r->f;
  const double *restrict im = ms->inv_mass;
  r->substeps++;
  for (size_t w = 0; w < words((r->nsprings + 3) / 4); w++)
    r->block_evals += (uint64_t)__builtin_popcountll(r->blk_bits[w]);
  mass_spring_forces_subset(ms, x, v, f, r->blk_bits, r->act_bits);
  /* Kick: the awake nodes, and the sleeping ones whose force wakes them
   * (NaN wakes too, so the step's guard sees it). */
  const double fw2 = r->force_wake * r->force_wake;
  size_t nl = 0;
  for (size_t w = 0; w < words(r->n); w++)
    for (uint64_t bits = r->act_bits[w]; bits; bits &= bits - 1) {
      const size_t k = 64 * w + (size_t)__builtin_ctzll(bits);
      const double *fk = f + 3 * k;
      if (!r->awake[k] && (im[k] == 0 || fk[0] * fk[0] + fk[1] * fk[1] + fk[2] * fk[2] <= fw2)) continue;
      r->list[nl++] = (uint32_t)k;
      const double hw = h * im[k];
      v[3 * k] += hw * fk[0];
      v[3 * k + 1] += hw * fk[1];
      v[3 * k + 2] += hw * fk[2];
    }
  if (ms->fs.correct_v) ms->fs.correct_v(&ms->fs, h); /* its nodes were touched: awake */
  /* Drift. */
  for (size_t a = 0; a < nl; a++) {
    const size_t k = r->list[a];
    x[3 * k] += h * v[3 * k];
    x[3 * k + 1] += h * v[3 * k + 1];
    x[3 * k + 2] += h * v[3 * k + 2];
  }
  r->node_updates += nl;
  /* The decisions, after the sub-step (its sets were fixed for it): the
   * woken nodes are held; the nodes that fell asleep in the last sub-step
   * and stayed asleep are released (their rows and neighbours' forces were
   * evaluated once more, at their final positions); the quiet ones fall
   * asleep, held for one sub-step. */
  for (size_t a = 0; a < nl; a++) {
    const size_t k = r->list[a];
    if (!r->awake[k]) wake(r, k);
  }
  for (size_t a = 0; a < r->npend; a++)
    if (!r->awake[r->pend[a]]) release(r, r->pend[a]);
  const double fs2 = 0.25 * fw2, vs2 = r->speed_sleep * r->speed_sleep;
  size_t np = 0;
  for (size_t a = 0; a < nl; a++) {
    const size_t k = r->list[a];
    double *vk = v + 3 * k;
    const double *fk = f + 3 * k;
    const int quiet = !r->touched[k] && vk[0] * vk[0] + vk[1] * vk[1] + vk[2] * vk[2] < vs2 &&
                      fk[0] * fk[0] + fk[1] * fk[1] + fk[2] * fk[2] < fs2;
    r->touched[k] = 0;
    if (!quiet) continue;
    r->awake[k] = 0;
    r->nawake--;
    r->sleeps++;
    vk[0] = vk[1] = vk[2] = 0;
    memcpy(r->xs + 3 * k, x + 3 * k, 3 * sizeof *x);
    r->pend2[np++] = (uint32_t)k;
  }
  uint32_t *t = r->pend;
  r->pend = r->pend2;
  r->pend2 = t;
  r->npend = np;
}

/* 1 when some node held asleep is not where it fell asleep, at rest, bit
 * for bit: one branch-free pass over every node on the bit patterns
 * (integer operations: the floating-point compares cost twice as much). */
static int sleepers_moved(const ms_regions_t *r, const double *x, const double *v) {
  const double *xs = r->xs;
  const uint8_t *awake = r->awake;
  uint64_t bits_diff = 0;
  for (size_t k = 0; k < r->n; k++) {
    uint64_t a[3], b[3], u[3];
    memcpy(a, x + 3 * k, sizeof a);
    memcpy(b, xs + 3 * k, sizeof b);
    memcpy(u, v + 3 * k, sizeof u);
    const uint64_t asleep = (uint64_t)0 - (uint64_t)(awake[k] == 0);
    bits_diff |= asleep & ((a[0] ^ b[0]) | (a[1] ^ b[1]) | (a[2] ^ b[2]) | u[0] | u[1] | u[2]);
  }
  return bits_diff != 0;
}

int ms_regions_begin_step(ms_regions_t *r, mass_spring_t *ms, int written) {
  const double *x = ms->x, *v = ms->v;
  double sum = 0;
  r->sx = ms->x;
  r->sv = ms->v;
  r->gn = 0;
  r->in_step = 1;
  /* The sleeping nodes are looked at only after a write from outside: the
   * pass over every node cost as much as the awake nodes' forces, and
   * streamed the whole organ through the cache at every step. */
  int diff = 0;
  if (written) {
    r->sleeper_checks++;
    diff = sleepers_moved(r, x, v);
  }
#ifdef VISCERA_CHECK_OUTSIDE_WRITES
  /* Sanitizer builds check the writers' side of the contract (model.h
   * outside_writes): a write nobody noted would desynchronise the sleeping
   * nodes from the state without a trace. */
  if (!written && sleepers_moved(r, x, v)) {
    fprintf(stderr, "ms_regions: a sleeping node was written from outside the step without "
                    "model_note_outside_write\n");
    abort();
  }
#endif
  /* The awake ones (all among the act nodes) are kept for a rollback. */
  const uint8_t *awake = r->awake;
  for (size_t w = 0; w < words(r->n); w++)
    for (uint64_t bits = r->act_bits[w]; bits; bits &= bits - 1) {
      const size_t k = 64 * w + (size_t)__builtin_ctzll(bits), c = 3 * k;
      if (!awake[k]) continue;
      sum += x[c] + x[c + 1] + x[c + 2] + v[c] + v[c + 1] + v[c + 2];
      guard_save(r, k);
    }
  if (!diff && isfinite(sum)) return 0;
  for (size_t a = 0; a < r->gn; a++) r->saved[r->gidx[a]] = 0;
  r->gn = 0;
  r->in_step = 0;
  return -1;
}

int ms_regions_end_step(ms_regions_t *r, mass_spring_t *ms, uint64_t *rollbacks) {
  double sum = 0;
  for (size_t a = 0; a < r->gn; a++) {
    const size_t c = 3 * (size_t)r->gidx[a];
    sum += ms->x[c] + ms->x[c + 1] + ms->x[c + 2] + ms->v[c] + ms->v[c + 1] + ms->v[c + 2];
    r->saved[r->gidx[a]] = 0;
  }
  r->in_step = 0;
  if (isfinite(sum)) return 0;
  for (size_t a = 0; a < r->gn; a++) {
    memcpy(ms->x + 3 * (size_t)r->gidx[a], r->gx + 3 * a, 3 * sizeof(double));
    memcpy(ms->v + 3 * (size_t)r->gidx[a], r->gv + 3 * a, 3 * sizeof(double));
  }
  if (rollbacks) (*rollbacks)++;
  r->springs = NULL; /* derived again from the restored state */
  return -1;
}
