/* SPDX-License-Identifier: Apache-2.0 */
#include "session/checkpoint.h"

#include "runtime/checkpoint_state.h"
#include "state_blob.h"
#include "training/measures_blob.h"

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

/* The session's records in the core's state (runtime/checkpoint_state.h):
 * per tool, the measures of its session record (session_tool.h: tracker
 * measures and tally); after the stones, the tools' roles. On load they
 * are kept aside until the whole file checked out. */
typedef struct session_saved {
  const session_tool_t *tools;
  const tool_roles_t *roles; /* NULL: none saved */
} session_saved_t;

typedef struct session_records {
  const runtime_t *rt;
  session_tool_t *tools;
  tool_roles_t *roles; /* NULL: the file's are ignored */
  thr_tracker_t tmp[SCENE_MAX_TOOLS];
  tool_tally_t tl[SCENE_MAX_TOOLS];
  size_t nroles;
  struct {
    char owner[TOOL_ROLE_STATION_MAX], guide[TOOL_ROLE_STATION_MAX];
    double a, k;
  } role[SCENE_MAX_TOOLS];
} session_records_t;

/* Per tool: tracker measures, then tally (grasps, grasp_time), in the
 * layout of training/measures_blob.h. */
static void put_tool(void *ctx, buf_t *b, size_t t) {
  const session_saved_t *r = ctx;
  measures_blob_put(b, &r->tools[t].thr, r->tools[t].tally.grasps, r->tools[t].tally.grasp_time);
}

/* nroles (0 when saved without roles, else ntools), per tool:
 * owner[32] guide[32] authority coupling. */
static void put_tail(void *ctx, buf_t *b) {
  const session_saved_t *r = ctx;
  size_t nroles = r->roles ? r->roles->ntools : 0;
  sb_put_u64(b, nroles);
  for (size_t t = 0; t < nroles; t++) {
    const tool_role_t *tr = &r->roles->tool[t];
    char owner[TOOL_ROLE_STATION_MAX] = {0}, guide[TOOL_ROLE_STATION_MAX] = {0}; /* no stray bytes on disk */
    snprintf(owner, sizeof owner, "%s", tr->owner);
    snprintf(guide, sizeof guide, "%s", tr->guide);
    sb_put(b, owner, sizeof owner);
    sb_put(b, guide, sizeof guide);
    sb_put_f64(b, tr->authority);
    sb_put_f64(b, tr->coupling);
  }
}

static const char *get_tool(void *ctx, buf_t *b, size_t t) {
  session_records_t *r = ctx;
  thr_tracker_t *tr = &r->tmp[t];
  *tr = r->tools[t].thr; /* levels and live state stay the scene's */
  uint32_t grasps = 0;
  double grasp_time = 0;
  const char *bad = measures_blob_get(b, tr, &grasps, &grasp_time);
  if (bad) return bad;
  /* Not holding now: a grasp is not restored, so the next one counts anew. */
  r->tl[t] = (tool_tally_t){.grasps = grasps, .grasp_time = grasp_time, .was_holding = 0};
  return NULL;
}

static const char *get_tail(void *ctx, buf_t *b) {
  session_records_t *r = ctx;
  uint64_t nroles = sb_get_u64(b);
  if (nroles != 0 && nroles != r->rt->ntools) return "tool role count differs from the scene";
  r->nroles = (size_t)nroles;
  for (size_t t = 0; t < r->nroles; t++) {
    sb_get(b, r->role[t].owner, sizeof r->role[t].owner);
    sb_get(b, r->role[t].guide, sizeof r->role[t].guide);
    r->role[t].a = sb_get_f64(b);
    r->role[t].k = sb_get_f64(b);
    /* Names must end inside their field: a missing NUL is a crafted file. */
    if (b->bad || !memchr(r->role[t].owner, 0, sizeof r->role[t].owner) ||
        !memchr(r->role[t].guide, 0, sizeof r->role[t].guide) ||
        (r->roles && tool_roles_valid(r->roles, t, r->role[t].owner, r->role[t].guide, r->role[t].a, r->role[t].k)))
      return "bad tool role";
  }
  return NULL;
}

static void apply(void *ctx) {
  session_records_t *r = ctx;
  for (size_t t = 0; t < r->rt->ntools; t++) {
    r->tools[t].thr = r->tmp[t];
    r->tools[t].tally = r->tl[t];
  }
  if (r->roles)
    for (size_t t = 0; t < r->nroles; t++)
      tool_roles_restore(r->roles, t, r->role[t].owner, r->role[t].guide, r->role[t].a, r->role[t].k);
}

/* The whole file but its CRC in b, reusing b's buffer: the magic, then the
 * core's state with the session's records (runtime/checkpoint_state.c
 * gives the layout), then, appended by seal() (the checkpointer's writer
 * thread computes it, not the physics loop), the crc32 (as u64) of
 * everything before it. */
static int serialise(buf_t *b, const runtime_t *rt, const session_tool_t *tools, const tool_roles_t *roles,
                     verr_t *err) {
  b->len = 0;
  b->bad = 0;
  sb_put(b, MAGIC, 8);
  session_saved_t saved = {.tools = tools, .roles = roles};
  ckpt_session_io_t io = {.ctx = &saved, .put_tool = put_tool, .put_tail = put_tail};
  return ckpt_state_put(b, rt, &io, err);
}

int checkpoint_resume_state(state_blob_t *out, const runtime_t *rt, const session_tool_t *tools, verr_t *err) {
  session_saved_t saved = {.tools = tools, .roles = NULL};
  ckpt_session_io_t io = {.ctx = &saved, .put_tool = put_tool};
  return ckpt_state_put(out, rt, &io, err);
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

int checkpoint_save(const char *path, const runtime_t *rt, const session_tool_t *tools, const tool_roles_t *roles,
                    verr_t *err) {
  buf_t b = {0};
  int bad = serialise(&b, rt, tools, roles, err);
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

void checkpointer_submit(checkpointer_t *c, const runtime_t *rt, const session_tool_t *tools,
                         const tool_roles_t *roles) {
  /* Never block the physics loop: if the writer holds the lock right now,
   * skip this checkpoint; the next one comes soon. */
  if (pthread_mutex_trylock(&c->lock)) return;
  verr_t err;
  if (serialise(&c->pending, rt, tools, roles, &err) == 0) {
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

int checkpoint_load(const char *path, runtime_t *rt, session_tool_t *tools, tool_roles_t *roles, verr_t *err) {
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
  session_records_t rec = {.rt = rt, .tools = tools, .roles = roles};
  ckpt_session_io_t io = {.ctx = &rec, .get_tool = get_tool, .get_tail = get_tail, .apply = apply};
  char what[200];
  int rc = ckpt_state_get(&b, rt, &io, what, sizeof what, err);
  if (rc == -1) return refuse(&b, err, path, what);
  free(b.p);
  if (rc == -2) return -2;
  if (rc == -3) {
    size_t len = strlen(err->msg);
    snprintf(err->msg + len, sizeof err->msg - len, " (checkpoint %.200s; starting from rest)", path);
    return -1;
  }
  return 1;
}
