/* SPDX-License-Identifier: Apache-2.0 */
#include "session/applied_outbox.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* A queued sample: this header, then the sample's struct (its sequences'
 * buffers meaningless), its tools, its controls; len covers all of it and
 * is a multiple of 8, so every record starts 8-aligned. len 0 marks the
 * unused end of the ring before a wrap. */
typedef struct record {
  uint32_t len, ntools, ncontrols, pad;
} record_t;

struct applied_outbox {
  dds_entity_t writer;
  unsigned char *ring; /* APPLIED_OUTBOX_BYTES */
  /* Bytes ever queued (producer) and ever taken (consumer): the ring holds
   * [tail, head) modulo its size. */
  _Atomic uint64_t head, tail;
  atomic_int stop;
  uint64_t period_ns;
  pthread_mutex_t lock; /* with wake: lets stop cut the thread's wait short */
  pthread_cond_t wake;
  pthread_t thread;
  uint64_t dropped;           /* producer's */
  uint64_t published, failed; /* consumer's, read after the join */
};

static size_t record_len(uint32_t ntools, uint32_t ncontrols) {
  size_t n = sizeof(record_t) + sizeof(viscera_AppliedInput) + ntools * sizeof(viscera_AppliedTool) +
             ncontrols * sizeof(viscera_AppliedControl);
  return (n + 7u) & ~(size_t)7u;
}

int applied_outbox_push(applied_outbox_t *o, const viscera_AppliedInput *s) {
  const uint32_t nt = s->tools._length, nc = s->controls._length;
  const size_t need = record_len(nt, nc), cap = APPLIED_OUTBOX_BYTES;
  uint64_t head = atomic_load_explicit(&o->head, memory_order_relaxed);
  const uint64_t tail = atomic_load_explicit(&o->tail, memory_order_acquire);
  size_t pos = (size_t)(head % cap), skip = cap - pos < need ? cap - pos : 0;
  if (cap - (size_t)(head - tail) < skip + need) {
    o->dropped++;
    return -1;
  }
  if (skip) {
    memset(o->ring + pos, 0, sizeof(uint32_t)); /* len 0: wrap */
    head += skip;
    pos = 0;
  }
  unsigned char *p = o->ring + pos;
  const record_t r = {.len = (uint32_t)need, .ntools = nt, .ncontrols = nc};
  memcpy(p, &r, sizeof r);
  p += sizeof r;
  memcpy(p, s, sizeof *s);
  p += sizeof *s;
  if (nt) memcpy(p, s->tools._buffer, nt * sizeof(viscera_AppliedTool));
  p += nt * sizeof(viscera_AppliedTool);
  if (nc) memcpy(p, s->controls._buffer, nc * sizeof(viscera_AppliedControl));
  atomic_store_explicit(&o->head, head + need, memory_order_release);
  return 0;
}

/* Writes every record queued now, in order. The sample's sequences point
 * into the ring (records are 8-aligned; the producer does not reuse a
 * record's bytes before tail passes it, after the write). */
static void drain(applied_outbox_t *o) {
  const size_t cap = APPLIED_OUTBOX_BYTES;
  const uint64_t head = atomic_load_explicit(&o->head, memory_order_acquire);
  uint64_t tail = atomic_load_explicit(&o->tail, memory_order_relaxed);
  while (tail < head) {
    const unsigned char *p = o->ring + tail % cap;
    record_t r;
    memcpy(&r.len, p, sizeof r.len);
    if (r.len == 0) { /* the rest of the ring is unused: go round */
      tail += cap - tail % cap;
      continue;
    }
    memcpy(&r, p, sizeof r);
    p += sizeof r;
    viscera_AppliedInput s;
    memcpy(&s, p, sizeof s);
    p += sizeof s;
    s.tools._buffer = (viscera_AppliedTool *)(uintptr_t)p;
    p += r.ntools * sizeof(viscera_AppliedTool);
    s.controls._buffer = (viscera_AppliedControl *)(uintptr_t)p;
    s.tools._length = s.tools._maximum = r.ntools;
    s.tools._release = false;
    s.controls._length = s.controls._maximum = r.ncontrols;
    s.controls._release = false;
    if (dds_write(o->writer, &s) >= 0)
      o->published++;
    else
      o->failed++;
    tail += r.len;
    atomic_store_explicit(&o->tail, tail, memory_order_release);
  }
}

static void *outbox_main(void *arg) {
  applied_outbox_t *o = arg;
  for (;;) {
    /* Read before the drain: whatever was pushed before stop is written. */
    const int stop = atomic_load(&o->stop);
    drain(o);
    if (stop) break;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    uint64_t ns = (uint64_t)ts.tv_nsec + o->period_ns;
    ts.tv_sec += (time_t)(ns / 1000000000u);
    ts.tv_nsec = (long)(ns % 1000000000u);
    pthread_mutex_lock(&o->lock);
    if (!atomic_load(&o->stop)) pthread_cond_timedwait(&o->wake, &o->lock, &ts);
    pthread_mutex_unlock(&o->lock);
  }
  return NULL;
}

applied_outbox_t *applied_outbox_start(dds_entity_t writer, uint64_t period_ns, verr_t *err) {
  applied_outbox_t *o = calloc(1, sizeof *o);
  if (o) o->ring = malloc(APPLIED_OUTBOX_BYTES);
  if (!o || !o->ring) {
    if (o) free(o);
    return verr_set(err, "applied inputs: out of memory"), NULL;
  }
  /* Resident now, not page by page during the session (the server's
   * memory figures would show the ring's first lap as growth). */
  memset(o->ring, 0, APPLIED_OUTBOX_BYTES);
  o->writer = writer;
  o->period_ns = period_ns;
  atomic_init(&o->head, 0);
  atomic_init(&o->tail, 0);
  atomic_init(&o->stop, 0);
  pthread_condattr_t ca;
  pthread_condattr_init(&ca);
  pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
  pthread_cond_init(&o->wake, &ca);
  pthread_condattr_destroy(&ca);
  pthread_mutex_init(&o->lock, NULL);
  if (pthread_create(&o->thread, NULL, outbox_main, o)) {
    pthread_cond_destroy(&o->wake);
    pthread_mutex_destroy(&o->lock);
    free(o->ring);
    free(o);
    return verr_set(err, "applied inputs: cannot start the writer thread"), NULL;
  }
  return o;
}

void applied_outbox_stop(applied_outbox_t *o, uint64_t *published, uint64_t *failed) {
  if (!o) return;
  pthread_mutex_lock(&o->lock);
  atomic_store(&o->stop, 1);
  pthread_cond_signal(&o->wake);
  pthread_mutex_unlock(&o->lock);
  pthread_join(o->thread, NULL);
  pthread_cond_destroy(&o->wake);
  pthread_mutex_destroy(&o->lock);
  if (published) *published = o->published;
  if (failed) *failed = o->failed + o->dropped;
  free(o->ring);
  free(o);
}
