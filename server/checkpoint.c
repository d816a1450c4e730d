#include "checkpoint.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MAGIC "VSCKPT01"
#define MAX_FILE (1u << 30) /* far above any interactive scene; bounds what a bad file makes us read */

/* Little builder/reader over one byte buffer; the file is written and read
 * in one piece, so a truncated file fails the length and CRC checks. */
typedef struct buf {
  unsigned char *p;
  size_t len, cap, at;
  int bad;
} buf_t;

static void put(buf_t *b, const void *src, size_t n) {
  if (b->bad) return;
  if (b->len + n > b->cap) {
    size_t cap = b->cap ? b->cap : 4096;
    while (cap < b->len + n) cap *= 2;
    unsigned char *p = realloc(b->p, cap);
    if (!p) {
      b->bad = 1;
      return;
    }
    b->p = p;
    b->cap = cap;
  }
  memcpy(b->p + b->len, src, n);
  b->len += n;
}
static void put_u64(buf_t *b, uint64_t v) { put(b, &v, sizeof v); }
static void put_f64(buf_t *b, double v) { put(b, &v, sizeof v); }

static int get(buf_t *b, void *dst, size_t n) {
  if (b->bad || n > b->len - b->at) return b->bad = 1, -1;
  memcpy(dst, b->p + b->at, n);
  b->at += n;
  return 0;
}
static uint64_t get_u64(buf_t *b) {
  uint64_t v = 0;
  get(b, &v, sizeof v);
  return v;
}
static double get_f64(buf_t *b) {
  double v = 0;
  get(b, &v, sizeof v);
  return v;
}

static uint32_t crc32(const unsigned char *p, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; i++) {
    c ^= p[i];
    for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return ~c;
}

static void put_tracker(buf_t *b, const thr_tracker_t *t) {
  for (int k = 0; k < THR_COUNT; k++) {
    put_f64(b, t->time_above[k]);
    put_u64(b, t->crossings[k]);
  }
  put_f64(b, t->peak_force);
  put_f64(b, t->contact_time);
  put_f64(b, t->contact_force_integral);
  put_f64(b, t->path_length);
}

/* The whole state as bytes (CRC included) in b, reusing its buffer. */
static int serialise(buf_t *b, const runtime_t *rt, const thr_tracker_t *thr) {
  b->len = 0;
  b->bad = 0;
  char name[SCENE_NAME_LEN] = {0};
  snprintf(name, sizeof name, "%s", rt->scene.name);
  put(b, MAGIC, 8);
  put(b, name, sizeof name);
  put_f64(b, rt->sim_time);
  put_u64(b, rt->steps);
  put_u64(b, rt->norgans);
  for (size_t i = 0; i < rt->norgans; i++) {
    const model_t *m = rt->organs[i].model;
    put_u64(b, m->nnodes);
    put_u64(b, m->topology_version);
    put(b, m->x, 3 * m->nnodes * sizeof(double));
    put(b, m->v, 3 * m->nnodes * sizeof(double));
  }
  put_u64(b, rt->ntools);
  for (size_t t = 0; t < rt->ntools; t++) put_tracker(b, &thr[t]);
  uint64_t crc = b->bad ? 0 : crc32(b->p, b->len);
  put_u64(b, crc);
  return b->bad ? -1 : 0;
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

int checkpoint_save(const char *path, const runtime_t *rt, const thr_tracker_t *thr, verr_t *err) {
  buf_t b = {0};
  if (serialise(&b, rt, thr)) {
    free(b.p);
    return verr_set(err, "checkpoint: out of memory");
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
  uint64_t written, failed;
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
    int rc = write_atomic(c->path, c->writing.p, c->writing.len, &err);
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

void checkpointer_submit(checkpointer_t *c, const runtime_t *rt, const thr_tracker_t *thr) {
  /* Never block the physics loop: if the writer holds the lock right now,
   * skip this checkpoint; the next one comes soon. */
  if (pthread_mutex_trylock(&c->lock)) return;
  if (serialise(&c->pending, rt, thr) == 0) {
    c->have_pending = 1;
    pthread_cond_signal(&c->cond);
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

int checkpoint_load(const char *path, runtime_t *rt, thr_tracker_t *thr, verr_t *err) {
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
      put(&b, chunk, n);
  }
  int rerr = ferror(f);
  fclose(f);
  if (rerr || b.bad) return refuse(&b, err, path, "cannot read (or larger than any scene's state)");
  if (b.len < 8 + SCENE_NAME_LEN + 8 || memcmp(b.p, MAGIC, 8))
    return refuse(&b, err, path, "not a viscera checkpoint (bad magic)");
  uint64_t stored_crc;
  memcpy(&stored_crc, b.p + b.len - 8, 8);
  if (stored_crc != crc32(b.p, b.len - 8)) return refuse(&b, err, path, "damaged (CRC mismatch: truncated or corrupt)");
  b.len -= 8;
  b.at = 8;
  char name[SCENE_NAME_LEN];
  get(&b, name, sizeof name);
  name[SCENE_NAME_LEN - 1] = 0;
  if (strcmp(name, rt->scene.name)) return refuse(&b, err, path, "written for another scene");
  double sim_time = get_f64(&b);
  uint64_t steps = get_u64(&b);
  if (get_u64(&b) != rt->norgans) return refuse(&b, err, path, "organ count differs from the scene");
  /* First pass: check everything; only then change the runtime, so a bad
   * file leaves it untouched. */
  size_t organ_at[SCENE_MAX_ORGANS];
  for (size_t i = 0; i < rt->norgans; i++) {
    const model_t *m = rt->organs[i].model;
    uint64_t nn = get_u64(&b), topo = get_u64(&b);
    if (b.bad || nn != m->nnodes || topo != m->topology_version)
      return refuse(&b, err, path, "node count or topology differs from the scene's models (cut or refined organ)");
    organ_at[i] = b.at;
    size_t bytes = 6 * nn * sizeof(double);
    if (bytes > b.len - b.at) return refuse(&b, err, path, "truncated organ state");
    for (size_t k = 0; k < 6 * nn; k++) {
      double v;
      memcpy(&v, b.p + b.at + k * sizeof v, sizeof v);
      if (!isfinite(v)) return refuse(&b, err, path, "non-finite organ state");
    }
    b.at += bytes;
  }
  if (get_u64(&b) != rt->ntools) return refuse(&b, err, path, "tool count differs from the scene");
  if (b.bad || !isfinite(sim_time) || sim_time < 0) return refuse(&b, err, path, "bad header values");
  thr_tracker_t tmp[SCENE_MAX_TOOLS];
  for (size_t t = 0; t < rt->ntools; t++) {
    thr_tracker_t *tr = &tmp[t];
    *tr = thr[t]; /* levels and live state stay the scene's */
    for (int k = 0; k < THR_COUNT; k++) {
      tr->time_above[k] = get_f64(&b);
      tr->crossings[k] = (uint32_t)get_u64(&b);
    }
    tr->peak_force = get_f64(&b);
    tr->contact_time = get_f64(&b);
    tr->contact_force_integral = get_f64(&b);
    tr->path_length = get_f64(&b);
    double sum = tr->peak_force + tr->contact_time + tr->contact_force_integral + tr->path_length;
    for (int k = 0; k < THR_COUNT; k++) sum += tr->time_above[k];
    if (!isfinite(sum) || tr->peak_force < 0 || tr->contact_time < 0 || tr->path_length < 0)
      return refuse(&b, err, path, "bad tool measures");
  }
  if (b.bad || b.at != b.len) return refuse(&b, err, path, "truncated or trailing data");
  for (size_t i = 0; i < rt->norgans; i++) {
    model_t *m = rt->organs[i].model;
    memcpy(m->x, b.p + organ_at[i], 3 * m->nnodes * sizeof(double));
    memcpy(m->v, b.p + organ_at[i] + 3 * m->nnodes * sizeof(double), 3 * m->nnodes * sizeof(double));
  }
  for (size_t t = 0; t < rt->ntools; t++) thr[t] = tmp[t];
  rt->sim_time = sim_time;
  rt->steps = steps;
  free(b.p);
  return 1;
}
