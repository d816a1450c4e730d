#include "checkpoint.h"

#include "state_blob.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MAGIC "VSCKPT02"
#define MAGIC_PREFIX "VSCKPT" /* + two digits: the format version */
#define MAX_FILE (1u << 30)   /* far above any interactive scene; bounds what a bad file makes us read */

/* The file is built and read in one piece (state_blob.h), so a truncated
 * file fails the length and CRC checks. */
typedef state_blob_t buf_t;

/* CRC-32 (IEEE), a byte at a time from a table built on first use: a
 * cut organ's checkpoint is some 300 kB, 8 x faster than bit by bit. The
 * table is built before any thread runs (checkpoint_load or
 * checkpointer_start, from the server's main thread). */
static uint32_t crc_table[256];
static void crc_init(void) {
  if (crc_table[1]) return;
  for (uint32_t i = 0; i < 256; i++) {
    uint32_t c = i;
    for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    crc_table[i] = c;
  }
}
static uint32_t crc32(const unsigned char *p, size_t n) {
  crc_init();
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; i++) c = crc_table[(c ^ p[i]) & 0xffu] ^ (c >> 8);
  return ~c;
}
/* Appends the CRC of everything in b. */
static void seal(buf_t *b) {
  uint64_t crc = b->bad ? 0 : crc32(b->p, b->len);
  sb_put_u64(b, crc);
}

static void put_tracker(buf_t *b, const thr_tracker_t *t) {
  for (int k = 0; k < THR_COUNT; k++) {
    sb_put_f64(b, t->time_above[k]);
    sb_put_u64(b, t->crossings[k]);
  }
  sb_put_f64(b, t->peak_force);
  sb_put_f64(b, t->contact_time);
  sb_put_f64(b, t->contact_force_integral);
  sb_put_f64(b, t->path_length);
}

/* The whole state as bytes (CRC included) in b, reusing its buffer.
 * Layout (native byte order, version 2):
 *   magic[8] scene_name[64] sim_time steps
 *   norgans, per organ: nnodes topology_version x[3 nnodes] v[3 nnodes]
 *                       (topology_version > 0: nbytes, the model's topology bytes)
 *   ntools, per tool: tracker measures, tally (grasps, grasp_time)
 *   ntasks, per task: started completed t_start t_end
 *   nstones, per stone: pos[3] held_by removed
 *   nroles (0 when saved without roles, else ntools), per tool:
 *     owner[32] guide[32] authority coupling
 *   crc32 (as u64) of everything before it (seal(): the checkpointer's
 *   writer thread computes it, not the physics loop). */
static int serialise(buf_t *b, const runtime_t *rt, const thr_tracker_t *thr, const tool_tally_t *tally,
                     const tool_roles_t *roles, verr_t *err) {
  b->len = 0;
  b->bad = 0;
  char name[SCENE_NAME_LEN] = {0};
  snprintf(name, sizeof name, "%s", rt->scene.name);
  sb_put(b, MAGIC, 8);
  sb_put(b, name, sizeof name);
  sb_put_f64(b, rt->sim_time);
  sb_put_u64(b, rt->steps);
  sb_put_u64(b, rt->norgans);
  for (size_t i = 0; i < rt->norgans; i++) {
    const model_t *m = rt->organs[i].model;
    sb_put_u64(b, m->nnodes);
    sb_put_u64(b, m->topology_version);
    sb_put(b, m->x, 3 * m->nnodes * sizeof(double));
    sb_put(b, m->v, 3 * m->nnodes * sizeof(double));
    if (m->topology_version == 0) continue;
    if (!m->ops->save_topology)
      return verr_set(err,
                      "organ '%s': its %s model cannot save a changed topology (topology %u): checkpoints stop here",
                      rt->organs[i].cfg->name, m->ops->name, m->topology_version);
    size_t at = b->len;
    sb_put_u64(b, 0); /* length, filled below */
    if (m->ops->save_topology(m, b))
      return verr_set(err, "organ '%s': cannot save its topology%s", rt->organs[i].cfg->name,
                      b->bad ? " (out of memory)" : "");
    if (!b->bad) {
      uint64_t nbytes = b->len - at - 8;
      memcpy(b->p + at, &nbytes, 8);
    }
  }
  sb_put_u64(b, rt->ntools);
  for (size_t t = 0; t < rt->ntools; t++) {
    put_tracker(b, &thr[t]);
    sb_put_u64(b, tally[t].grasps);
    sb_put_f64(b, tally[t].grasp_time);
  }
  sb_put_u64(b, rt->ntasks);
  for (size_t k = 0; k < rt->ntasks; k++) {
    const task_rt_t *t = &rt->tasks[k];
    sb_put_u64(b, (uint64_t)t->started);
    sb_put_u64(b, (uint64_t)t->completed);
    sb_put_f64(b, t->t_start);
    sb_put_f64(b, t->t_end);
  }
  sb_put_u64(b, rt->nstones);
  for (size_t k = 0; k < rt->nstones; k++) {
    const stone_t *st = &rt->stones[k];
    sb_put(b, st->pos, sizeof st->pos);
    sb_put_u64(b, (uint64_t)(int64_t)st->held_by);
    sb_put_u64(b, (uint64_t)st->removed);
  }
  size_t nroles = roles ? roles->ntools : 0;
  sb_put_u64(b, nroles);
  for (size_t t = 0; t < nroles; t++) {
    const tool_role_t *tr = &roles->tool[t];
    char owner[TOOL_ROLE_STATION_MAX] = {0}, guide[TOOL_ROLE_STATION_MAX] = {0}; /* no stray bytes on disk */
    snprintf(owner, sizeof owner, "%s", tr->owner);
    snprintf(guide, sizeof guide, "%s", tr->guide);
    sb_put(b, owner, sizeof owner);
    sb_put(b, guide, sizeof guide);
    sb_put_f64(b, tr->authority);
    sb_put_f64(b, tr->coupling);
  }
  return b->bad ? verr_set(err, "checkpoint: out of memory") : 0;
}

static int write_atomic(const char *path, const unsigned char *p, size_t len, verr_t *err) {
  char tmp[SCENE_PATH_LEN + 16];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  int rc = fd < 0 ? -1 : 0, e = errno;
  for (size_t done = 0; rc == 0 && done < len;) {
    ssize_t w = write(fd, p + done, len - done);
    if (w <= 0)
      rc = -1, e = w < 0 ? errno : ENOSPC;
    else
      done += (size_t)w;
  }
  /* fsync before rename: otherwise a power cut can leave the new name
   * pointing at an empty file and the previous checkpoint gone. */
  if (rc == 0 && fsync(fd)) rc = -1, e = errno;
  if (fd >= 0 && close(fd) && rc == 0) rc = -1, e = errno;
  if (rc == 0 && rename(tmp, path)) rc = -1, e = errno;
  if (rc) {
    unlink(tmp);
    return verr_set(err, "checkpoint %s: cannot write: %s", path, strerror(e));
  }
  return 0;
}

int checkpoint_save(const char *path, const runtime_t *rt, const thr_tracker_t *thr, const tool_tally_t *tally,
                    const tool_roles_t *roles, verr_t *err) {
  buf_t b = {0};
  int bad = serialise(&b, rt, thr, tally, roles, err);
  if (!bad) {
    seal(&b);
    if (b.bad) bad = verr_set(err, "checkpoint: out of memory");
  }
  if (bad) {
    free(b.p);
    return -1;
  }
  int rc = write_atomic(path, b.p, b.len, err);
  free(b.p);
  return rc;
}

/* Background writer: the physics thread serialises into `pending` (a copy
 * of some 100 kB: microseconds) and the thread does the slow part (write,
 * fsync: milliseconds to tens of them) so the 1 kHz loop never waits on
 * the disk. A submission while the previous one is still being written
 * replaces the pending bytes: only the newest state matters. */
struct checkpointer {
  char path[SCENE_PATH_LEN];
  pthread_t thread;
  pthread_mutex_t lock;
  pthread_cond_t cond;
  buf_t pending, writing;
  int have_pending, stop;
  uint64_t written, failed, refused;
  char last_error[sizeof(((verr_t *)0)->msg)];
};

static void *writer_main(void *arg) {
  checkpointer_t *c = arg;
  pthread_mutex_lock(&c->lock);
  for (;;) {
    while (!c->have_pending && !c->stop) pthread_cond_wait(&c->cond, &c->lock);
    if (!c->have_pending && c->stop) break;
    buf_t t = c->writing; /* swap: the loop fills the other buffer meanwhile */
    c->writing = c->pending;
    c->pending = t;
    c->have_pending = 0;
    pthread_mutex_unlock(&c->lock);
    verr_t err;
    seal(&c->writing);
    int rc = c->writing.bad ? verr_set(&err, "checkpoint: out of memory")
                            : write_atomic(c->path, c->writing.p, c->writing.len, &err);
    pthread_mutex_lock(&c->lock);
    if (rc) {
      c->failed++;
      snprintf(c->last_error, sizeof c->last_error, "%s", err.msg);
    } else {
      c->written++;
    }
  }
  pthread_mutex_unlock(&c->lock);
  return NULL;
}

checkpointer_t *checkpointer_start(const char *path, verr_t *err) {
  crc_init(); /* before the writer thread exists (see crc32) */
  checkpointer_t *c = calloc(1, sizeof *c);
  if (!c) return verr_set(err, "checkpoint: out of memory"), NULL;
  if (strlen(path) >= sizeof c->path) {
    free(c);
    return verr_set(err, "checkpoint: path too long: %s", path), NULL;
  }
  snprintf(c->path, sizeof c->path, "%s", path);
  pthread_mutex_init(&c->lock, NULL);
  pthread_cond_init(&c->cond, NULL);
  if (pthread_create(&c->thread, NULL, writer_main, c)) {
    pthread_mutex_destroy(&c->lock);
    pthread_cond_destroy(&c->cond);
    free(c);
    return verr_set(err, "checkpoint: cannot start the writer thread"), NULL;
  }
  return c;
}

void checkpointer_submit(checkpointer_t *c, const runtime_t *rt, const thr_tracker_t *thr, const tool_tally_t *tally,
                         const tool_roles_t *roles) {
  /* Never block the physics loop: if the writer holds the lock right now,
   * skip this checkpoint; the next one comes soon. */
  if (pthread_mutex_trylock(&c->lock)) return;
  verr_t err;
  if (serialise(&c->pending, rt, thr, tally, roles, &err) == 0) {
    c->have_pending = 1;
    pthread_cond_signal(&c->cond);
  } else if (c->refused++ == 0) {
    /* The state cannot be saved (a model without topology hooks changed
     * its topology): the file keeps the last state that could; said once. */
    fprintf(stderr, "checkpoint %s: %s; the file keeps the last state saved\n", c->path, err.msg);
  }
  pthread_mutex_unlock(&c->lock);
}

int checkpointer_stop(checkpointer_t *c, uint64_t *written, verr_t *err) {
  if (!c) return 0;
  pthread_mutex_lock(&c->lock);
  c->stop = 1;
  pthread_cond_signal(&c->cond);
  pthread_mutex_unlock(&c->lock);
  pthread_join(c->thread, NULL);
  int rc = c->failed ? -1 : 0;
  if (rc) verr_set(err, "%llu checkpoint write(s) failed, last: %s", (unsigned long long)c->failed, c->last_error);
  if (written) *written = c->written;
  free(c->pending.p);
  free(c->writing.p);
  pthread_mutex_destroy(&c->lock);
  pthread_cond_destroy(&c->cond);
  free(c);
  return rc;
}

static int refuse(buf_t *b, verr_t *err, const char *path, const char *what) {
  free(b->p);
  return verr_set(err, "checkpoint %s: %s; starting from rest", path, what);
}

/* Where one organ's saved state sits in the file (load's first pass). */
typedef struct organ_at {
  size_t nnodes, x, v; /* offsets of x and v */
  uint64_t topo;       /* saved topology_version */
  size_t blob, nblob;  /* the model's topology bytes */
} organ_at_t;

/* After a topology restore failed, other organs may already be restored:
 * the runtime is built again from its scene, so a refused file still
 * means "starting from rest". */
static int rebuild_at_rest(runtime_t *rt, verr_t *err) {
  scene_t *sc = malloc(sizeof *sc);
  if (!sc) return verr_set(err, "out of memory");
  *sc = rt->scene;
  runtime_destroy(rt);
  int rc = runtime_init(rt, sc, err);
  free(sc);
  return rc;
}

/* Restores the changed topologies (organs with topo > 0); 0, or -1 with
 * err (rt rebuilt at rest: a hook that fails after its checks may have
 * changed its model), or -2 when the rebuild failed too. */
static int restore_topologies(runtime_t *rt, const buf_t *b, const organ_at_t *at, verr_t *err) {
  for (size_t i = 0; i < rt->norgans; i++) {
    if (at[i].topo == 0) continue;
    model_t *m = rt->organs[i].model;
    size_t bytes = 3 * at[i].nnodes * sizeof(double);
    double *x = malloc(bytes ? bytes : 1), *v = malloc(bytes ? bytes : 1);
    buf_t tb = {.p = b->p + at[i].blob, .len = at[i].nblob};
    verr_t sub;
    int rc = -1;
    if (!x || !v) {
      verr_set(&sub, "out of memory");
    } else {
      memcpy(x, b->p + at[i].x, bytes); /* aligned copies: the file's offsets need not be */
      memcpy(v, b->p + at[i].v, bytes);
      rc = m->ops->restore_topology(m, &tb, at[i].nnodes, x, v, &sub);
      if (rc == 0 && (tb.at != tb.len || m->nnodes != at[i].nnodes)) {
        verr_set(&sub, "topology data of unexpected length");
        rc = -1;
      }
    }
    free(x);
    free(v);
    if (rc) {
      verr_set(err, "organ '%s': cannot restore its topology: %s", rt->organs[i].cfg->name, sub.msg);
      verr_t e2;
      return rebuild_at_rest(rt, &e2) ? -2 : -1;
    }
    runtime_topology_restored(rt, i);
  }
  return 0;
}

int checkpoint_load(const char *path, runtime_t *rt, thr_tracker_t *thr, tool_tally_t *tally, tool_roles_t *roles,
                    verr_t *err) {
  FILE *f = fopen(path, "rb");
  if (!f) {
    if (errno == ENOENT) return 0;
    return verr_set(err, "checkpoint %s: cannot open: %s; starting from rest", path, strerror(errno));
  }
  buf_t b = {0};
  unsigned char chunk[65536];
  size_t n;
  while ((n = fread(chunk, 1, sizeof chunk, f)) > 0 && !b.bad) {
    if (b.len + n > MAX_FILE)
      b.bad = 1;
    else
      sb_put(&b, chunk, n);
  }
  int rerr = ferror(f);
  fclose(f);
  if (rerr || b.bad) return refuse(&b, err, path, "cannot read (or larger than any scene's state)");
  if (b.len >= 8 && !memcmp(b.p, MAGIC_PREFIX, 6) && memcmp(b.p, MAGIC, 8)) {
    char what[96];
    snprintf(what, sizeof what, "written in checkpoint format %.2s, this server reads format %.2s only",
             (const char *)b.p + 6, MAGIC + 6);
    return refuse(&b, err, path, what);
  }
  if (b.len < 8 + SCENE_NAME_LEN + 8 || memcmp(b.p, MAGIC, 8))
    return refuse(&b, err, path, "not a viscera checkpoint (bad magic)");
  uint64_t stored_crc;
  memcpy(&stored_crc, b.p + b.len - 8, 8);
  if (stored_crc != crc32(b.p, b.len - 8)) return refuse(&b, err, path, "damaged (CRC mismatch: truncated or corrupt)");
  b.len -= 8;
  b.at = 8;
  char name[SCENE_NAME_LEN];
  sb_get(&b, name, sizeof name);
  name[SCENE_NAME_LEN - 1] = 0;
  if (strcmp(name, rt->scene.name)) return refuse(&b, err, path, "written for another scene");
  double sim_time = sb_get_f64(&b);
  uint64_t steps = sb_get_u64(&b);
  if (sb_get_u64(&b) != rt->norgans) return refuse(&b, err, path, "organ count differs from the scene");
  /* First pass: check everything; only then change the runtime, so a bad
   * file leaves it untouched. */
  organ_at_t at[SCENE_MAX_ORGANS];
  char what[200];
  for (size_t i = 0; i < rt->norgans; i++) {
    const model_t *m = rt->organs[i].model;
    size_t nn = sb_count(&b, 48);
    uint64_t topo = sb_get_u64(&b);
    if (b.bad) return refuse(&b, err, path, "truncated organ state (or a node count beyond the file)");
    if (topo == 0 && nn != m->nnodes)
      return refuse(&b, err, path, "node count differs from the scene's models (another organ mesh?)");
    if (topo > UINT32_MAX) return refuse(&b, err, path, "bad topology version");
    if (topo > 0 && !m->ops->restore_topology) {
      snprintf(what, sizeof what, "organ '%s' changed its topology and its %s model cannot restore one",
               rt->organs[i].cfg->name, m->ops->name);
      return refuse(&b, err, path, what);
    }
    at[i] = (organ_at_t){.nnodes = nn, .topo = topo, .x = b.at, .v = b.at + 3 * nn * sizeof(double)};
    size_t bytes = 6 * nn * sizeof(double);
    for (size_t k = 0; k < 6 * nn; k++) {
      double v;
      memcpy(&v, b.p + b.at + k * sizeof v, sizeof v);
      if (!isfinite(v)) return refuse(&b, err, path, "non-finite organ state");
    }
    b.at += bytes;
    if (topo > 0) {
      at[i].nblob = sb_count(&b, 1);
      at[i].blob = b.at;
      b.at += at[i].nblob;
      if (b.bad) return refuse(&b, err, path, "truncated topology data");
    }
  }
  if (sb_get_u64(&b) != rt->ntools) return refuse(&b, err, path, "tool count differs from the scene");
  if (b.bad || !isfinite(sim_time) || sim_time < 0) return refuse(&b, err, path, "bad header values");
  thr_tracker_t tmp[SCENE_MAX_TOOLS];
  tool_tally_t tl[SCENE_MAX_TOOLS];
  for (size_t t = 0; t < rt->ntools; t++) {
    thr_tracker_t *tr = &tmp[t];
    *tr = thr[t]; /* levels and live state stay the scene's */
    for (int k = 0; k < THR_COUNT; k++) {
      tr->time_above[k] = sb_get_f64(&b);
      tr->crossings[k] = (uint32_t)sb_get_u64(&b);
    }
    tr->peak_force = sb_get_f64(&b);
    tr->contact_time = sb_get_f64(&b);
    tr->contact_force_integral = sb_get_f64(&b);
    tr->path_length = sb_get_f64(&b);
    double sum = tr->peak_force + tr->contact_time + tr->contact_force_integral + tr->path_length;
    for (int k = 0; k < THR_COUNT; k++) sum += tr->time_above[k];
    if (!isfinite(sum) || tr->peak_force < 0 || tr->contact_time < 0 || tr->path_length < 0)
      return refuse(&b, err, path, "bad tool measures");
    uint64_t grasps = sb_get_u64(&b);
    double grasp_time = sb_get_f64(&b);
    if (grasps > UINT32_MAX || !isfinite(grasp_time) || grasp_time < 0) return refuse(&b, err, path, "bad tool tally");
    /* Not holding now: a grasp is not restored, so the next one counts anew. */
    tl[t] = (tool_tally_t){.grasps = (uint32_t)grasps, .grasp_time = grasp_time, .was_holding = 0};
  }
  if (sb_get_u64(&b) != rt->ntasks) return refuse(&b, err, path, "task count differs from the scene");
  task_rt_t tasks[SCENE_MAX_TASKS];
  for (size_t k = 0; k < rt->ntasks; k++) {
    uint64_t started = sb_get_u64(&b), completed = sb_get_u64(&b);
    double t0 = sb_get_f64(&b), t1 = sb_get_f64(&b);
    if (b.bad || started > 1 || completed > started || !isfinite(t0) || !isfinite(t1) || t0 < 0 ||
        (completed && t1 < t0) || t0 > sim_time)
      return refuse(&b, err, path, "bad task state");
    tasks[k] = rt->tasks[k];
    tasks[k].started = (int)started;
    tasks[k].completed = (int)completed;
    tasks[k].t_start = t0;
    tasks[k].t_end = t1;
  }
  if (sb_get_u64(&b) != rt->nstones) return refuse(&b, err, path, "object count differs from the scene");
  double stone_pos[SCENE_MAX_OBJECTS][3];
  int removed[SCENE_MAX_OBJECTS];
  for (size_t k = 0; k < rt->nstones; k++) {
    sb_get(&b, stone_pos[k], sizeof stone_pos[k]);
    int64_t held = (int64_t)sb_get_u64(&b);
    uint64_t rem = sb_get_u64(&b);
    if (b.bad || !isfinite(stone_pos[k][0] + stone_pos[k][1] + stone_pos[k][2]) || held < -1 ||
        held >= (int64_t)rt->ntools || rem > 1)
      return refuse(&b, err, path, "bad object state");
    removed[k] = (int)rem;
  }
  uint64_t nroles = sb_get_u64(&b);
  if (nroles != 0 && nroles != rt->ntools) return refuse(&b, err, path, "tool role count differs from the scene");
  struct {
    char owner[TOOL_ROLE_STATION_MAX], guide[TOOL_ROLE_STATION_MAX];
    double a, k;
  } role[SCENE_MAX_TOOLS];
  for (size_t t = 0; t < nroles; t++) {
    sb_get(&b, role[t].owner, sizeof role[t].owner);
    sb_get(&b, role[t].guide, sizeof role[t].guide);
    role[t].a = sb_get_f64(&b);
    role[t].k = sb_get_f64(&b);
    /* Names must end inside their field: a missing NUL is a crafted file. */
    if (b.bad || !memchr(role[t].owner, 0, sizeof role[t].owner) || !memchr(role[t].guide, 0, sizeof role[t].guide) ||
        (roles && tool_roles_valid(roles, t, role[t].owner, role[t].guide, role[t].a, role[t].k)))
      return refuse(&b, err, path, "bad tool role");
  }
  if (b.bad || b.at != b.len) return refuse(&b, err, path, "truncated or trailing data");
  int rc = restore_topologies(rt, &b, at, err);
  if (rc) {
    free(b.p);
    if (rc == -2) return -2;
    size_t len = strlen(err->msg);
    snprintf(err->msg + len, sizeof err->msg - len, " (checkpoint %.200s; starting from rest)", path);
    return -1;
  }
  for (size_t i = 0; i < rt->norgans; i++) {
    if (at[i].topo > 0) continue; /* restore_topology took its positions */
    model_t *m = rt->organs[i].model;
    memcpy(m->x, b.p + at[i].x, 3 * m->nnodes * sizeof(double));
    memcpy(m->v, b.p + at[i].v, 3 * m->nnodes * sizeof(double));
  }
  for (size_t t = 0; t < rt->ntools; t++) {
    thr[t] = tmp[t];
    tally[t] = tl[t];
  }
  memcpy(rt->tasks, tasks, rt->ntasks * sizeof tasks[0]);
  for (size_t k = 0; k < rt->nstones; k++) {
    stone_t *st = &rt->stones[k];
    memcpy(st->pos, stone_pos[k], sizeof st->pos);
    st->held_by = -1; /* tools re-enter from outside: a held stone is dropped where it was */
    st->removed = removed[k];
    memset(st->force, 0, sizeof st->force);
  }
  if (roles)
    for (size_t t = 0; t < nroles; t++)
      tool_roles_restore(roles, t, role[t].owner, role[t].guide, role[t].a, role[t].k);
  rt->sim_time = sim_time;
  rt->steps = steps;
  free(b.p);
  return 1;
}
