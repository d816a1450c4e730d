/* SPDX-License-Identifier: Apache-2.0 */
/* Recording files, good and bad.
 *
 * Writes a recording with the store (as the recorder does), reads it back
 * with recfile, then damages copies of it every way a file gets damaged:
 * missing, empty, a directory, garbage, another SQLite database, truncated
 * at many lengths, overwritten with junk in places. For each, both the
 * library and the viscera-recinfo binary must give a clear error naming the
 * file (exit status 1) or a salvage, and never crash (no signal, no
 * sanitizer report). */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <sqlite3.h>

#include "check.h"
#include "recording/recfile.h"
#include "recording/recording.h"
#include "recording/store.h"
#include "viscera.h"

#define N_SAMPLES 6000

static char dir[256];

static void path_in(char *buf, size_t size, const char *name) { snprintf(buf, size, "%s/%s", dir, name); }

static long file_size(const char *p) {
  struct stat sb;
  return stat(p, &sb) == 0 ? (long)sb.st_size : -1;
}

static int copy_prefix(const char *from, const char *to, long n) {
  FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
  int ok = a && b;
  for (long i = 0; ok && i < n; i++) {
    int ch = fgetc(a);
    if (ch == EOF) break;
    fputc(ch, b);
  }
  if (a) fclose(a);
  if (b) fclose(b);
  return ok ? 0 : -1;
}

/* A recording shaped like a real one: one topic with the product's
 * ToolCommand descriptor, two writers, mixed kinds, sample sizes that
 * include overflow pages. */
static void make_recording(const char *p) {
  verr_t err = {{0}};
  store_t *s = NULL;
  store_session_t meta = {"unit", "viscera/unit", 42, 1700000000000000000LL, "host", "test"};
  CHECK(store_open(&s, p, false, &meta, &err) == 0);
  if (!s) {
    fprintf(stderr, "%s\n", err.msg);
    return;
  }
  /* refuses to overwrite */
  store_t *s2 = NULL;
  CHECK(store_open(&s2, p, false, &meta, &err) < 0);
  CHECK(strstr(err.msg, "file exists") != NULL);
  int64_t tid = 0, w1 = 0, w2 = 0;
  CHECK(store_add_topic(s, "viscera_ToolCommand", &viscera_ToolCommand_desc, NULL, 1, &tid, &err) == 0);
  uint8_t g1[16] = {1}, g2[16] = {2};
  CHECK(store_add_writer(s, tid, g1, "viscera/unit", 1, &w1, &err) == 0);
  CHECK(store_add_writer(s, tid, g2, NULL, 1, &w2, &err) == 0);
  static unsigned char cdr[20000];
  for (size_t i = 0; i < sizeof cdr; i++) cdr[i] = (unsigned char)(i * 7);
  cdr[0] = 0;
  cdr[1] = 1;
  for (int i = 0; i < N_SAMPLES; i++) {
    store_sample_t smp = {tid,
                          (i % 2) ? w1 : w2,
                          1700000000000000000LL + 1000LL * i,
                          1700000000000000000LL + 1000LL * i,
                          (i % 500 == 499) ? REC_KIND_DISPOSE : REC_KIND_DATA,
                          false,
                          cdr,
                          (i % 100 == 0) ? 15000u : 64u};
    if (store_add_sample(s, &smp, &err) < 0) {
      CHECK(0);
      fprintf(stderr, "%s\n", err.msg);
      break;
    }
  }
  CHECK(store_close(s, 1700000001000000000LL, &err) == 0);
}

typedef struct count_ctx {
  uint64_t rows, bytes;
  int64_t last_id;
  int order_errors;
} count_ctx_t;

static int count_row(void *arg, const recfile_row_t *r) {
  count_ctx_t *c = arg;
  c->rows++;
  c->bytes += r->cdr_len;
  if (r->id <= c->last_id) c->order_errors++;
  c->last_id = r->id;
  if (r->cdr && r->cdr_len >= 2) c->bytes += ((const unsigned char *)r->cdr)[1] == 1 ? 0 : 1000000;
  return 0;
}

/* Runs viscera-recinfo on `p`; returns its exit status, or -1 for a
 * signal or a sanitizer report (both count as a crash). */
static int run_recinfo(const char *p, const char *extra, char *errtext, size_t errsize) {
  char errpath[512];
  path_in(errpath, sizeof errpath, "recinfo.err");
  pid_t pid = fork();
  if (pid == 0) {
    int fd = open(errpath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int nul = open("/dev/null", O_WRONLY);
    if (fd < 0 || nul < 0) _exit(126);
    dup2(nul, 1);
    dup2(fd, 2);
    if (extra)
      execl(RECINFO_EXE, RECINFO_EXE, p, extra, (char *)NULL);
    else
      execl(RECINFO_EXE, RECINFO_EXE, p, (char *)NULL);
    _exit(127);
  }
  int st = 0;
  waitpid(pid, &st, 0);
  errtext[0] = 0;
  FILE *f = fopen(errpath, "r");
  if (f) {
    size_t n = fread(errtext, 1, errsize - 1, f);
    errtext[n] = 0;
    fclose(f);
  }
  if (WIFSIGNALED(st)) {
    fprintf(stderr, "recinfo on %s died of signal %d\n", p, WTERMSIG(st));
    return -1;
  }
  if (strstr(errtext, "Sanitizer") || strstr(errtext, "runtime error")) {
    fprintf(stderr, "recinfo on %s: sanitizer report:\n%s\n", p, errtext);
    return -1;
  }
  return WEXITSTATUS(st);
}

/* A file that is not a usable recording: library error naming it, binary
 * exit 1 with the same kind of message. */
static void expect_rejected(const char *p, const char *what) {
  verr_t err = {{0}};
  recfile_t *rf = NULL;
  CHECK(recfile_open(&rf, p, &err) < 0);
  CHECK(rf == NULL);
  CHECK(strstr(err.msg, p) == err.msg);
  CHECK(strstr(err.msg, what) != NULL);
  if (!strstr(err.msg, what)) fprintf(stderr, "  %s: got '%s', expected '%s'\n", p, err.msg, what);
  recfile_close(rf);
  char text[4096];
  int rc = run_recinfo(p, NULL, text, sizeof text);
  CHECK(rc == 1);
  CHECK(strstr(text, p) != NULL);
  CHECK(strstr(text, what) != NULL);
}

/* A damaged copy: either rejected with a message naming the file, or
 * opened and salvaged; never a crash; the binary exits 0 or 1 (0 only
 * when nothing damaged was met). Returns rows salvaged, or -1 rejected. */
static long try_damaged(const char *p, bool *reported_damage) {
  verr_t err = {{0}};
  recfile_t *rf = NULL;
  long rows = -1;
  *reported_damage = true;
  if (recfile_open(&rf, p, &err) == 0) {
    count_ctx_t c = {0};
    recfile_scan_report_t rep;
    recfile_scan(rf, 0, true, count_row, &c, &rep);
    CHECK(c.order_errors == 0);
    CHECK(c.rows == rep.rows);
    rows = (long)c.rows;
    *reported_damage = rep.damaged || rep.invalid || recfile_damaged(rf);
    recfile_close(rf);
  } else {
    CHECK(strstr(err.msg, p) == err.msg);
  }
  char text[4096];
  int rc = run_recinfo(p, "--check-monotonic", text, sizeof text);
  CHECK(rc == 0 || rc == 1);
  if (rc == 1) CHECK(strstr(text, p) != NULL);
  if (rc != 0 && rc != 1) fprintf(stderr, "  %s: recinfo exit %d\n%s\n", p, rc, text);
  return rows;
}

int main(void) {
  snprintf(dir, sizeof dir, "/tmp/test_recinfo_XXXXXX");
  if (!mkdtemp(dir)) {
    perror("mkdtemp");
    return 1;
  }
  char good[512], p[512];
  path_in(good, sizeof good, "good.db");
  make_recording(good);

  /* the good file reads completely */
  {
    verr_t err = {{0}};
    recfile_t *rf = NULL;
    CHECK(recfile_open(&rf, good, &err) == 0);
    if (rf) {
      CHECK(!recfile_damaged(rf));
      CHECK(recfile_warnings(rf)[0] == 0);
      const recfile_session_t *s = recfile_session(rf);
      CHECK(s->valid && s->domain == 42 && s->has_end);
      CHECK(strcmp(s->partition, "viscera/unit") == 0);
      CHECK(recfile_topic_count(rf) == 1);
      const recfile_topic_t *t = recfile_topic_by_name(rf, "viscera_ToolCommand");
      CHECK(t && t->writers == 2 && strcmp(t->type_name, "viscera::ToolCommand") == 0);
      count_ctx_t c = {0};
      recfile_scan_report_t rep;
      recfile_scan(rf, 0, true, count_row, &c, &rep);
      CHECK(c.rows == N_SAMPLES && rep.damaged == 0 && rep.invalid == 0 && !rep.gave_up);
      CHECK(c.order_errors == 0);
      recfile_close(rf);
    }
    char text[4096];
    CHECK(run_recinfo(good, "--check-monotonic", text, sizeof text) == 0);
    /* a clean close leaves one self-contained file */
    char wal[600];
    snprintf(wal, sizeof wal, "%s-wal", good);
    CHECK(access(wal, F_OK) != 0);
  }

  /* not recordings at all */
  path_in(p, sizeof p, "missing.db");
  expect_rejected(p, "No such file");
  path_in(p, sizeof p, "empty.db");
  fclose(fopen(p, "w"));
  expect_rejected(p, "empty file");
  path_in(p, sizeof p, "adir.db");
  mkdir(p, 0755);
  expect_rejected(p, "is a directory");
  path_in(p, sizeof p, "garbage.db");
  {
    FILE *f = fopen(p, "wb");
    for (int i = 0; i < 70000; i++) fputc((i * 131 + 7) & 0xff, f);
    fclose(f);
  }
  expect_rejected(p, "not a SQLite database");
  path_in(p, sizeof p, "short_header.db");
  copy_prefix(good, p, 10);
  expect_rejected(p, "not a SQLite database");
  path_in(p, sizeof p, "other.db");
  {
    sqlite3 *db = NULL;
    sqlite3_open(p, &db);
    sqlite3_exec(db, "CREATE TABLE t (x); INSERT INTO t VALUES (1);", NULL, NULL, NULL);
    sqlite3_close(db);
  }
  expect_rejected(p, "not a viscera recording");
  /* a recording whose samples table is gone: named as damaged */
  path_in(p, sizeof p, "nosamples.db");
  copy_prefix(good, p, file_size(good));
  {
    sqlite3 *db = NULL;
    sqlite3_open(p, &db);
    sqlite3_exec(db, "DROP TABLE samples;", NULL, NULL, NULL);
    sqlite3_close(db);
  }
  expect_rejected(p, "damaged viscera recording");

  /* a recorder killed or still running: its committed batches are in the
   * -wal file; the main file copied alone holds no table, and the message
   * names the missing -wal instead of "not a viscera recording" */
  {
    char live[512];
    path_in(live, sizeof live, "live.db");
    verr_t err = {{0}};
    store_t *s = NULL;
    store_session_t meta = {"unit", "viscera/unit", 42, 1700000000000000000LL, "host", "test"};
    CHECK(store_open(&s, live, false, &meta, &err) == 0);
    int64_t tid = 0;
    if (s) CHECK(store_add_topic(s, "viscera_ToolCommand", &viscera_ToolCommand_desc, NULL, 1, &tid, &err) == 0);
    static unsigned char cdr[64] = {0, 1};
    for (int i = 0; s && i < 100; i++) {
      store_sample_t smp = {tid, 0,         1700000000000000000LL + i, 1700000000000000000LL + i, REC_KIND_DATA, false,
                            cdr, sizeof cdr};
      CHECK(store_add_sample(s, &smp, &err) == 0);
    }
    if (s) CHECK(store_commit(s, &err) == 0);
    path_in(p, sizeof p, "copied_without_wal.db");
    copy_prefix(live, p, file_size(live));
    char want[600];
    snprintf(want, sizeof want, "%s-wal, which is missing", p);
    expect_rejected(p, want);
    /* beside its -wal the same file reads, all 100 samples */
    recfile_t *rf = NULL;
    CHECK(recfile_open(&rf, live, &err) == 0);
    if (rf) {
      count_ctx_t c = {0};
      recfile_scan_report_t rep;
      recfile_scan(rf, 0, true, count_row, &c, &rep);
      CHECK(c.rows == 100);
      recfile_close(rf);
    }
    if (s) store_close(s, -1, &err);
  }

  /* truncated copies: never a crash; a salvage never claims more rows than
   * the file had, and a cut file never passes as undamaged */
  long size = file_size(good);
  CHECK(size > 100000);
  long cuts[] = {1,         16,   99,    100,      101,      512,      4096,           8191,
                 8192,      8193, 16384, size / 4, size / 3, size / 2, (2 * size) / 3, size - 8192,
                 size - 100};
  int salvaged = 0;
  for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
    snprintf(p, sizeof p, "%s/cut_%ld.db", dir, cuts[i]);
    copy_prefix(good, p, cuts[i]);
    bool damage = false;
    long rows = try_damaged(p, &damage);
    CHECK(rows <= N_SAMPLES);
    if (rows >= 0 && rows < N_SAMPLES) CHECK(damage);
    if (rows > 0) salvaged++;
    printf("cut at %7ld bytes: %s, %ld rows\n", cuts[i], rows < 0 ? "rejected" : "opened", rows);
  }
  /* the later cuts leave most of the samples readable */
  CHECK(salvaged >= 3);

  /* junk written over parts of a copy */
  unsigned long long x = 0x9e3779b97f4a7c15ULL;
  for (int k = 0; k < 24; k++) {
    snprintf(p, sizeof p, "%s/junk_%d.db", dir, k);
    copy_prefix(good, p, size);
    FILE *f = fopen(p, "r+b");
    for (int j = 0; j < 4; j++) {
      x = x * 6364136223846793005ULL + 1442695040888963407ULL;
      /* k < 4: hit page 1 (header and schema); otherwise anywhere */
      long at = k < 4 ? (long)((x >> 33) % 8192) : (long)((x >> 33) % (unsigned long long)size);
      fseek(f, at, SEEK_SET);
      for (int b = 0; b < 64; b++) {
        x = x * 6364136223846793005ULL + 1442695040888963407ULL;
        fputc((int)(x >> 56), f);
      }
    }
    fclose(f);
    bool damage = false;
    long rows = try_damaged(p, &damage);
    CHECK(rows <= N_SAMPLES);
  }

  /* leave nothing behind */
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
  return check_report("test_recinfo_files");
}
