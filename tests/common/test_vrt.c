/* SPDX-License-Identifier: Apache-2.0 */
/* vrt (common/vrt.h): the --rt-priority parser, and vrt_enter on a thread of
 * its own: granted, that thread alone runs SCHED_FIFO at the priority and a
 * thread it creates afterwards starts as SCHED_OTHER (RESET_ON_FORK); refused
 * (an unprivileged run), the thread is unchanged and the reason is printed.
 * Both outcomes are checked, whichever this machine gives. */
#define _GNU_SOURCE
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include "check.h"
#include "vrt.h"

static int policy_of_self(int *prio) {
  struct sched_param sp;
  int pol = sched_getscheduler(0);
  sched_getparam(0, &sp);
  *prio = sp.sched_priority;
  return pol;
}

typedef struct probe {
  int policy, prio;
} probe_t;

static void *child_probe(void *arg) {
  probe_t *p = arg;
  p->policy = policy_of_self(&p->prio);
  return NULL;
}

typedef struct rt_run {
  int asked;
  int granted;
  vrt_status_t st;
  int policy, prio;         /* this thread after vrt_enter */
  probe_t child;            /* a thread it created afterwards */
  char printed[1024];       /* vrt_report's output, not quiet */
  char printed_quiet[1024]; /* and quiet */
} rt_run_t;

static void capture(const vrt_status_t *st, int quiet, char *buf, size_t cap) {
  FILE *f = tmpfile();
  buf[0] = 0;
  if (!f) return;
  vrt_report(st, "unit", "test loop", quiet, f);
  rewind(f);
  size_t n = fread(buf, 1, cap - 1, f);
  buf[n] = 0;
  fclose(f);
}

static void *rt_thread(void *arg) {
  rt_run_t *r = arg;
  r->granted = vrt_enter(r->asked, &r->st);
  r->policy = policy_of_self(&r->prio);
  pthread_t c;
  if (pthread_create(&c, NULL, child_probe, &r->child) == 0) pthread_join(c, NULL);
  capture(&r->st, 0, r->printed, sizeof r->printed);
  capture(&r->st, 1, r->printed_quiet, sizeof r->printed_quiet);
  return NULL;
}

static void test_parse(void) {
  int p = -7;
  CHECK(vrt_parse_priority("1", &p) == 0 && p == 1);
  CHECK(vrt_parse_priority("99", &p) == 0 && p == 99);
  CHECK(vrt_parse_priority("70", &p) == 0 && p == 70);
  p = -7;
  const char *bad[] = {"0", "100", "x", "", "1.5", "-3", "+5", " 5", "5 ", "10x", "99999999999999999999"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) CHECK(vrt_parse_priority(bad[i], &p) == -1);
  CHECK(p == -7); /* untouched on error */
  CHECK(vrt_parse_priority(NULL, &p) == -1);
}

static void test_out_of_range_refused(void) {
  vrt_status_t st;
  CHECK(vrt_enter(0, &st) == 0);
  CHECK(!st.granted && strstr(st.why, "outside 1..99"));
  CHECK(vrt_enter(100, &st) == 0);
  int prio;
  CHECK(policy_of_self(&prio) == SCHED_OTHER);
}

static void test_enter(void) {
  rt_run_t r;
  memset(&r, 0, sizeof r);
  r.asked = 11;
  pthread_t t;
  CHECK(pthread_create(&t, NULL, rt_thread, &r) == 0);
  pthread_join(t, NULL);
  int main_prio;
  CHECK(policy_of_self(&main_prio) == SCHED_OTHER); /* only the calling thread changes */
  CHECK(r.granted == r.st.granted && r.st.priority == 11);
  if (r.granted) {
    printf("granted: %s", r.printed);
    CHECK((r.policy & ~SCHED_RESET_ON_FORK) == SCHED_FIFO);
    CHECK(r.policy & SCHED_RESET_ON_FORK);
    CHECK(r.prio == 11);
    CHECK(r.child.policy == SCHED_OTHER && r.child.prio == 0);
    CHECK(strstr(r.printed, "unit: test loop at SCHED_FIFO priority 11, ") != NULL);
    CHECK(strstr(r.printed_quiet, "at SCHED_FIFO priority") == NULL); /* quiet: only warnings */
#if defined(__SANITIZE_ADDRESS__)
    CHECK(r.st.mem == VRT_MEM_NONE && strstr(r.st.mem_note, "AddressSanitizer"));
    CHECK(strstr(r.printed_quiet, "unit: warning: memory not fully locked (AddressSanitizer") != NULL);
#else
    /* Whatever was locked, a partial lock says why and a full one does not. */
    CHECK((r.st.mem == VRT_MEM_ALL) == (r.st.mem_note[0] == 0));
    CHECK((r.st.mem_note[0] != 0) == (strstr(r.printed_quiet, "warning: memory not fully locked") != NULL));
    if (r.st.mem != VRT_MEM_NONE) munlockall();
#endif
  } else {
    printf("refused: %s", r.printed);
    CHECK(r.policy == SCHED_OTHER && r.prio == 0);
    CHECK(r.st.why[0] != 0 && r.st.mem == VRT_MEM_NONE);
    CHECK(strstr(r.printed, "unit: warning: SCHED_FIFO 11 refused (") != NULL);
    CHECK(strstr(r.printed, "running at normal priority") != NULL);
    CHECK(strcmp(r.printed, r.printed_quiet) == 0); /* a refusal is printed even when quiet */
  }
}

int main(void) {
  test_parse();
  test_out_of_range_refused();
  test_enter();
  return check_report("test_vrt");
}
