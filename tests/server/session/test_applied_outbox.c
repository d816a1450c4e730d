/* SPDX-License-Identifier: Apache-2.0 */
/* applied_outbox (server/session/applied_outbox.h) over real Cyclone DDS
 * (a writer and a reader of viscera_AppliedInput in one participant, the
 * loopback configuration, domain 166):
 * - 3,000 samples of 0-16 tools and now and then 1-3 controls, pushed in
 *   bursts while the thread writes every 2 ms (the ring wraps many times):
 *   every one arrives, in order, with its header, tools and controls equal
 *   to what was pushed; none dropped;
 * - a thread that waits between rounds: pushes of the largest sample
 *   fill the ring, the next push is refused and counted; stop writes every
 *   queued sample and counts the drop. The thread then waits an hour
 *   between rounds: a stop that did not wake it would hang the test until
 *   ctest's timeout fails it. */
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "dds/vdds.h"
#include "session/applied_input.h"
#include "session/applied_outbox.h"

static viscera_AppliedTool tools[APPLIED_MAX_TOOLS];
static viscera_AppliedControl controls[APPLIED_MAX_CONTROLS];

/* Sample i: its fields follow from i, so the reader can check them. */
static void make(viscera_AppliedInput *s, uint64_t i, uint32_t nt, uint32_t nc) {
  memset(s, 0, sizeof *s);
  s->tick = i;
  s->step = 3 * i;
  s->sim_time_ns = 1000000 * i;
  s->epoch = (uint32_t)(i / 1000);
  s->seq = i;
  for (uint32_t k = 0; k < nt; k++) {
    memset(&tools[k], 0, sizeof tools[k]);
    tools[k].tool_id = k;
    tools[k].position[0] = (double)i * 1e-3 + k;
    tools[k].orientation[0] = 1;
    tools[k].cmd_seq = 100 * i + k;
  }
  for (uint32_t k = 0; k < nc; k++) {
    memset(&controls[k], 0, sizeof controls[k]);
    controls[k].seq = 10 * i + k;
    controls[k].values[3] = (double)k;
    snprintf(controls[k].text, sizeof controls[k].text, "control %llu.%u", (unsigned long long)i, k);
    controls[k].task = -1;
  }
  s->tools._buffer = tools;
  s->tools._length = s->tools._maximum = nt;
  s->controls._buffer = controls;
  s->controls._length = s->controls._maximum = nc;
}

/* 1 when r is sample i as make() built it. */
static int same(const viscera_AppliedInput *r, uint64_t i, uint32_t nt, uint32_t nc) {
  int ok = r->tick == i && r->step == 3 * i && r->sim_time_ns == 1000000 * i && r->seq == i && r->tools._length == nt &&
           r->controls._length == nc;
  for (uint32_t k = 0; ok && k < nt; k++)
    ok = r->tools._buffer[k].tool_id == k && r->tools._buffer[k].position[0] == (double)i * 1e-3 + k &&
         r->tools._buffer[k].cmd_seq == 100 * i + k;
  for (uint32_t k = 0; ok && k < nc; k++) {
    char want[64];
    snprintf(want, sizeof want, "control %llu.%u", (unsigned long long)i, k);
    ok = r->controls._buffer[k].seq == 10 * i + k && r->controls._buffer[k].values[3] == (double)k &&
         !strcmp(r->controls._buffer[k].text, want);
  }
  return ok;
}

static uint32_t ntools_of(uint64_t i) { return (uint32_t)(i % (APPLIED_MAX_TOOLS + 1)); }
static uint32_t ncontrols_of(uint64_t i) { return i % 37 == 0 ? (uint32_t)(1 + i % 3) : 0; }

/* Takes what the reader has; checks each against the next expected index. */
static void take_all(dds_entity_t rd, uint64_t *next, size_t *bad, int full) {
  void *buf[64] = {0};
  dds_sample_info_t info[64];
  for (;;) {
    int n = dds_take(rd, buf, info, 64, 64);
    if (n <= 0) break;
    for (int k = 0; k < n; k++) {
      if (!info[k].valid_data) continue;
      const viscera_AppliedInput *r = buf[k];
      uint64_t i = *next;
      uint32_t nt = full ? APPLIED_MAX_TOOLS : ntools_of(i), nc = full ? APPLIED_MAX_CONTROLS : ncontrols_of(i);
      if (!same(r, i, nt, nc)) (*bad)++;
      (*next)++;
    }
    dds_return_loan(rd, buf, n);
  }
}

static void sleep_ms(long ms) {
  struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
  nanosleep(&ts, NULL);
}

int main(void) {
  vdds_t v;
  verr_t err;
  if (vdds_open(&v, 166, "outbox", &err)) {
    fprintf(stderr, "%s\n", err.msg);
    CHECK(!"DDS opens");
    return check_report("test_applied_outbox");
  }
  dds_entity_t wr = vdds_writer(&v, VT_APPLIED_INPUT, &err), rd = vdds_reader(&v, VT_APPLIED_INPUT, &err);
  CHECK(wr > 0 && rd > 0);

  /* Many samples through a wrapping ring, in order and intact. */
  applied_outbox_t *o = applied_outbox_start(wr, APPLIED_OUTBOX_PERIOD_NS, &err);
  CHECK(o != NULL);
  const uint64_t N = 3000;
  uint64_t next = 1, published = 0, failed = 0;
  size_t bad = 0, refused = 0;
  viscera_AppliedInput s;
  for (uint64_t i = 1; i <= N; i++) {
    make(&s, i, ntools_of(i), ncontrols_of(i));
    refused += applied_outbox_push(o, &s) != 0;
    if (i % 20 == 0) {
      sleep_ms(3);
      take_all(rd, &next, &bad, 0);
    }
  }
  applied_outbox_stop(o, &published, &failed);
  for (int k = 0; k < 100 && next <= N; k++) {
    take_all(rd, &next, &bad, 0);
    if (next <= N) sleep_ms(10);
  }
  printf("wrapping ring: %llu pushed, %zu refused, %llu written, %llu failed, %llu received in order, %zu differ\n",
         (unsigned long long)N, refused, (unsigned long long)published, (unsigned long long)failed,
         (unsigned long long)(next - 1), bad);
  CHECK(refused == 0 && published == N && failed == 0);
  CHECK(next == N + 1 && bad == 0);

  /* A slow thread: the ring fills, a push is refused, stop writes the rest at once. */
  o = applied_outbox_start(wr, 3600ull * 1000000000ull, &err);
  CHECK(o != NULL);
  sleep_ms(50); /* its first round is done (if not, it drains some of these: counted the same) */
  uint64_t queued = 0;
  int full = 0;
  for (uint64_t i = 1; i <= 10000 && !full; i++) {
    make(&s, i, APPLIED_MAX_TOOLS, APPLIED_MAX_CONTROLS);
    if (applied_outbox_push(o, &s) == 0)
      queued++;
    else
      full = 1;
  }
  applied_outbox_stop(o, &published, &failed);
  next = 1;
  bad = 0;
  for (int k = 0; k < 100 && next <= queued; k++) {
    take_all(rd, &next, &bad, 1);
    if (next <= queued) sleep_ms(10);
  }
  printf("full ring: %llu largest samples queued, then refused; stop wrote %llu (failed %llu), %llu received, %zu "
         "differ\n",
         (unsigned long long)queued, (unsigned long long)published, (unsigned long long)failed,
         (unsigned long long)(next - 1), bad);
  CHECK(full && queued > 10 && queued * 5000 < APPLIED_OUTBOX_BYTES * 2);
  CHECK(published == queued && failed == 1);
  CHECK(next == queued + 1 && bad == 0);
  vdds_close(&v);
  return check_report("test_applied_outbox");
}
