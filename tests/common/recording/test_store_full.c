/* SPDX-License-Identifier: Apache-2.0 */
/* The store on a full disk. A file-size limit (RLIMIT_FSIZE, with SIGXFSZ
 * ignored as the recorder does) makes writes fail with EFBIG the way a full
 * disk does, deterministically and without root. Asserts: the store stops
 * with a "disk full" error instead of crashing; what it reports saved is
 * exactly the committed batches (a multiple of the batch size); every later
 * write is refused; close fails but leaves one readable file (no WAL left)
 * holding exactly those samples and no end time. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "recording/recfile.h"
#include "recording/recording.h"
#include "recording/store.h"
#include "viscera.h"

#define BATCH 100u
#define LIMIT_BYTES (256u * 1024u)

static int count_row(void *arg, const recfile_row_t *r) {
  (void)r;
  (*(uint64_t *)arg)++;
  return 0;
}

int main(void) {
  char dir[] = "/tmp/viscera_store_full_XXXXXX";
  if (!mkdtemp(dir)) {
    perror("mkdtemp");
    return 1;
  }
  char path[512], wal[520];
  snprintf(path, sizeof path, "%s/full.db", dir);
  snprintf(wal, sizeof wal, "%s-wal", path);
  signal(SIGXFSZ, SIG_IGN);
  struct rlimit saved;
  getrlimit(RLIMIT_FSIZE, &saved);
  struct rlimit lim = saved;
  lim.rlim_cur = LIMIT_BYTES;
  if (saved.rlim_max != RLIM_INFINITY && saved.rlim_max < LIMIT_BYTES) lim.rlim_cur = saved.rlim_max;
  CHECK(setrlimit(RLIMIT_FSIZE, &lim) == 0);

  verr_t err = {{0}};
  store_t *s = NULL;
  store_session_t meta = {"unit", "viscera/unit", 42, 1700000000000000000LL, "host", "test"};
  CHECK(store_open(&s, path, false, &meta, &err) == 0);
  if (!s) {
    fprintf(stderr, "%s\n", err.msg);
    return check_report("test_store_full");
  }
  store_set_limits(s, (store_batch_limits_t){UINT64_MAX, BATCH, UINT64_MAX});
  int64_t tid = 0, wid = 0;
  CHECK(store_add_topic(s, "viscera_ToolCommand", &viscera_ToolCommand_desc, NULL, 1, &tid, &err) == 0);
  uint8_t g[16] = {7};
  CHECK(store_add_writer(s, tid, g, NULL, 1, &wid, &err) == 0);
  store_commit(s, &err);
  static unsigned char cdr[3000];
  for (size_t i = 0; i < sizeof cdr; i++) cdr[i] = (unsigned char)(i * 13 + 1);
  cdr[0] = 0, cdr[1] = 1;
  int failed_at = -1;
  for (int i = 0; i < 100000; i++) {
    store_sample_t smp = {tid, wid, 1000LL * i, 1000LL * i, REC_KIND_DATA, false, cdr, (i % 10 == 0) ? 3000u : 80u};
    if (store_add_sample(s, &smp, &err) < 0) {
      failed_at = i;
      break;
    }
  }
  printf("store stopped at sample %d: %s\n", failed_at, err.msg);
  CHECK(failed_at > (int)BATCH);
  CHECK(strstr(err.msg, "disk full") != NULL);
  CHECK(store_failed(s) && store_disk_full(s));
  uint64_t saved_samples = 0;
  store_counts(s, &saved_samples, NULL);
  printf("saved %llu samples\n", (unsigned long long)saved_samples);
  CHECK(saved_samples > 0 && saved_samples % BATCH == 0 && saved_samples <= (uint64_t)failed_at);
  /* stopped for good: later writes are refused with the same message */
  store_sample_t more = {tid, wid, 0, 0, REC_KIND_DATA, false, cdr, 80};
  verr_t err2 = {{0}};
  CHECK(store_add_sample(s, &more, &err2) < 0 && strstr(err2.msg, "disk full") != NULL);
  CHECK(store_commit(s, &err2) < 0);
  uint64_t after = 0;
  store_counts(s, &after, NULL);
  CHECK(after == saved_samples);
  CHECK(store_close(s, 1700000001000000000LL, &err2) < 0);
  CHECK(setrlimit(RLIMIT_FSIZE, &saved) == 0);

  struct stat sb;
  CHECK(stat(path, &sb) == 0 && (uint64_t)sb.st_size <= LIMIT_BYTES);
  CHECK(stat(wal, &sb) != 0 || sb.st_size == 0); /* checkpointed into the file */
  recfile_t *rf = NULL;
  CHECK(recfile_open(&rf, path, &err) == 0);
  if (rf) {
    CHECK(!recfile_damaged(rf));
    CHECK(recfile_session(rf)->valid && !recfile_session(rf)->has_end);
    uint64_t rows = 0;
    recfile_scan_report_t rep;
    recfile_scan(rf, 0, true, count_row, &rows, &rep);
    printf("recfile reads %llu samples\n", (unsigned long long)rows);
    CHECK(rows == saved_samples && rep.damaged == 0);
    recfile_close(rf);
  } else {
    fprintf(stderr, "%s\n", err.msg);
  }
  unlink(path);
  unlink(wal);
  char shm[520];
  snprintf(shm, sizeof shm, "%s-shm", path);
  unlink(shm);
  rmdir(dir);
  return check_report("test_store_full");
}
