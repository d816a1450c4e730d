/* SPDX-License-Identifier: Apache-2.0 */
/* flood_commands: a hostile participant against one seat (issue 15.1), and
 * the checker of what the seat's processes counted.
 *
 * flood DOMAIN PARTITION PIDS COUNT SECONDS
 *   Writes COUNT samples paced evenly over SECONDS (stopping at 2 x
 *   SECONDS whatever was sent), round robin: well-formed
 *   ToolCommands each for a new tool id (8, 9, ...), garbage (NaN
 *   positions) for tool 0, and well-formed commands for tool 0 from a
 *   writer announcing station "mallory" (tool 0 belongs to another
 *   station). Samples the resident set (/proc/PID/status VmRSS) of each
 *   process of PIDS (comma-separated: the server, and clients that read
 *   ToolCommand: a viewer, the trainee's haptic client) before (once every
 *   process has stopped growing: settle()), during and 1 s after, and
 *   fails when one grew by more than 8 MB at any time ($FLOOD_RSS_SLACK_KB
 *   overrides: the sanitized build's allocator adds a fixed few MB) or by
 *   more than 1.5 MB in the flood's second half. Prints "FLOOD
 *   sent_new_ids=... sent_garbage=... sent_impostor=... settled_s=...
 *   rssK_kb=before/half/max/after".
 *
 * reorder DOMAIN PARTITION PAIRS
 *   Issue 14.2: one anonymous writer sends PAIRS pairs of ToolCommands for
 *   tool 0 in free space, each pair newer first (seq 2, 1, 4, 3, ...),
 *   2 ms apart, as a reordering link would deliver them. DDS delivers all
 *   (they are in order on the wire); the server must apply the newer of
 *   each pair and skip the older: its INTAKE line, checked by
 *   `reorder-check SERVER_OUT PAIRS`, shows stale >= 90 % of PAIRS and
 *   commands + stale = what arrived.
 *
 * check SERVER_OUT HAPTIC_OUT FLOOD_OUT
 *   From the server's INTAKE line, the haptic client's SUMMARY line and the
 *   FLOOD line (the processes' own counters, never wall time): every kind
 *   of flood sample was dropped at the gate and counted; the owner's
 *   commands were applied (>= 75 % of the ticks it sent: a server stalled
 *   past its 32-deep history by a crowded machine loses some, flood or not;
 *   that a blocked writer's flood takes no place in the history is proven
 *   exactly in test_vdds_gate); the step kept
 *   its cost: the step thread's CPU time p99 (a counter of the process,
 *   blind to what the scheduler gave others) stays below the 1 ms step
 *   (or 5 x its median in a sanitized build).
 *   Overruns (falls 100 ms behind) are printed, not judged: on a crowded
 *   machine they happen without any flood. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/vdds.h"
#include "viscera.h"
#include "vtime.h"

/* Growth allowed over the flood: 8 MB, or $FLOOD_RSS_SLACK_KB (the
 * sanitized build's). The server's allocator and Cyclone's tables take a
 * fixed ~4 MB under any flood (4.2-4.3 MB at 25,000, 75,000 and 150,000
 * samples: a plateau) and more on a loaded machine; without the intake
 * gates 25,000 new ids cost 15 MB more. */
static long rss_slack_kb(void) {
  const char *e = getenv("FLOOD_RSS_SLACK_KB");
  return e && atol(e) > 0 ? atol(e) : 8192L;
}

/* Growth allowed in the flood's second half, whatever the build: a cost per
 * sample (a leak, an instance kept per tool id) grows there as much as in
 * the first half; a plateau does not. */
#define RSS_SECOND_HALF_KB 1536L

static long rss_kb(long pid) {
  char path[64], line[256];
  snprintf(path, sizeof path, "/proc/%ld/status", pid);
  FILE *f = fopen(path, "r");
  long kb = -1;
  if (!f) return -1;
  while (fgets(line, sizeof line, f))
    if (sscanf(line, "VmRSS: %ld", &kb) == 1) break;
  fclose(f);
  return kb;
}

static void command(viscera_ToolCommand *c, uint32_t tool, uint64_t seq, float x) {
  memset(c, 0, sizeof *c);
  c->tool_id = tool;
  c->seq = seq;
  c->client_mono_ns = vtime_mono_ns();
  c->position[0] = x;
  c->position[1] = 0.004f;
  c->position[2] = 0.07f;
  c->orientation[0] = 1;
  c->max_force = 4;
}

#define MAX_PIDS 4

/* Waits (at most 8 s) until no process of pid[] grew by more than 256 kB
 * in the last second, so the bound measures the flood and not a session
 * still warming up (a server just joined by its viewer and trainee grows
 * ~2 MB in its first seconds without any flood). Leaves the last reading
 * in rss[]; returns the seconds waited. */
static double settle(const long *pid, int npid, long *rss) {
  enum { PERIOD_MS = 250, WINDOW = 5, MAX_ROUNDS = 32 };
  long hist[WINDOW][MAX_PIDS];
  int round = 0;
  for (; round < MAX_ROUNDS; round++) {
    for (int k = 0; k < npid; k++) rss[k] = hist[round % WINDOW][k] = rss_kb(pid[k]);
    if (round >= WINDOW) {
      int grew = 0;
      for (int k = 0; k < npid; k++)
        if (rss[k] - hist[(round + 1) % WINDOW][k] > 256) grew = 1;
      if (!grew) break;
    }
    dds_sleepfor(DDS_MSECS(PERIOD_MS));
  }
  return round * PERIOD_MS * 1e-3;
}

static int flood(int argc, char **argv) {
  if (argc != 7) return 2;
  long pid[MAX_PIDS];
  int npid = 0;
  for (char *p = argv[4]; *p && npid < MAX_PIDS; p++) {
    pid[npid++] = strtol(p, &p, 10);
    if (*p != ',') break;
  }
  long count = atol(argv[5]);
  double seconds = atof(argv[6]);
  vdds_t v;
  verr_t err;
  if (vdds_open(&v, cli_parse_domain(argv[2]), argv[3], &err)) {
    fprintf(stderr, "flood_commands: %s\n", err.msg);
    return 1;
  }
  dds_entity_t w = vdds_writer(&v, VT_TOOL_COMMAND, &err);
  dds_entity_t w_mallory = vdds_writer_station(&v, VT_TOOL_COMMAND, "mallory", &err);
  if (w < 0 || w_mallory < 0) {
    fprintf(stderr, "flood_commands: %s\n", err.msg);
    return 1;
  }
  dds_sleepfor(DDS_MSECS(500)); /* discovery: the server's reader matches ours */
  long rss0[MAX_PIDS], rss_max[MAX_PIDS], rss_half[MAX_PIDS];
  double settle_s = settle(pid, npid, rss0);
  for (int k = 0; k < npid; k++) {
    rss_max[k] = rss_half[k] = rss0[k];
    if (rss0[k] <= 0) {
      fprintf(stderr, "flood_commands: cannot read the resident set of pid %ld\n", pid[k]);
      return 1;
    }
  }
  uint64_t sent[3] = {0, 0, 0}, seq = 0;
  uint64_t t0 = vtime_mono_ns(), until = t0 + (uint64_t)(2 * seconds * 1e9);
  double per_ns = (double)count / (seconds * 1e9);
  viscera_ToolCommand c;
  for (long i = 0; i < count && vtime_mono_ns() < until; i++) {
    switch (i % 3) {
    case 0: /* a new tool id every time: each would be an instance kept for good */
      command(&c, 8u + (uint32_t)sent[0], ++seq, 0.0f);
      break;
    case 1: /* garbage aimed at the owned tool */
      command(&c, 0, ++seq, NAN);
      break;
    default: /* well-formed, but from a station that does not own tool 0 */
      command(&c, 0, ++seq, 0.03f);
      break;
    }
    if (dds_write(i % 3 == 2 ? w_mallory : w, &c) >= 0) sent[i % 3]++;
    if (i % 100 == 99) { /* paced in batches: the rate of the flood, not the writer's top speed */
      uint64_t due = t0 + (uint64_t)((double)(i + 1) / per_ns);
      if (due > vtime_mono_ns()) vtime_sleep_until(due);
    }
    if (i % 5000 == 0 || i == count / 2)
      for (int k = 0; k < npid; k++) {
        long kb = rss_kb(pid[k]);
        if (kb > rss_max[k]) rss_max[k] = kb;
        if (i <= count / 2) rss_half[k] = rss_max[k];
      }
  }
  for (int t = 0; t < 10; t++) { /* memory given back, or never taken */
    dds_sleepfor(DDS_MSECS(100));
    for (int k = 0; k < npid; k++) {
      long kb = rss_kb(pid[k]);
      if (kb > rss_max[k]) rss_max[k] = kb;
    }
  }
  printf("FLOOD sent_new_ids=%" PRIu64 " sent_garbage=%" PRIu64 " sent_impostor=%" PRIu64 " settled_s=%.2f", sent[0],
         sent[1], sent[2], settle_s);
  int bad = 0;
  long slack = rss_slack_kb();
  for (int k = 0; k < npid; k++) {
    long rss1 = rss_kb(pid[k]);
    printf(" rss%d_kb=%ld/%ld/%ld/%ld", k, rss0[k], rss_half[k], rss_max[k], rss1);
    if (rss_max[k] - rss0[k] > slack || rss1 - rss0[k] > slack) {
      fprintf(stderr, "flood_commands: FAIL: the resident set of pid %ld grew from %ld kB to %ld kB (after: %ld kB)\n",
              pid[k], rss0[k], rss_max[k], rss1);
      bad = 1;
    }
    if (rss_max[k] - rss_half[k] > RSS_SECOND_HALF_KB) {
      fprintf(stderr,
              "flood_commands: FAIL: the resident set of pid %ld still grew in the flood's second half, from %ld kB "
              "to %ld kB (a cost per sample, not a plateau)\n",
              pid[k], rss_half[k], rss_max[k]);
      bad = 1;
    }
  }
  printf("\n");
  vdds_close(&v);
  return bad;
}

static int reorder(char **argv) {
  vdds_t v;
  verr_t err;
  if (vdds_open(&v, cli_parse_domain(argv[2]), argv[3], &err)) {
    fprintf(stderr, "flood_commands: %s\n", err.msg);
    return 1;
  }
  dds_entity_t w = vdds_writer(&v, VT_TOOL_COMMAND, &err);
  dds_entity_t r = vdds_reader(&v, VT_SCENE_INFO, &err);
  for (int i = 0; i < 2000; i++) { /* the server is up */
    void *s[1] = {0};
    dds_sample_info_t si;
    int n = dds_take(r, s, &si, 1, 1);
    if (n > 0) dds_return_loan(r, s, n);
    if (n > 0) break;
    dds_sleepfor(DDS_MSECS(10));
  }
  dds_sleepfor(DDS_MSECS(300));
  long pairs = atol(argv[4]);
  viscera_ToolCommand c;
  for (long i = 0; i < pairs; i++) {
    command(&c, 0, (uint64_t)(2 * i + 2), 0.001f * (float)(i % 10));
    dds_write(w, &c);
    command(&c, 0, (uint64_t)(2 * i + 1), 0.001f * (float)(i % 10));
    dds_write(w, &c);
    dds_sleepfor(DDS_MSECS(2));
  }
  dds_sleepfor(DDS_MSECS(200));
  vdds_close(&v);
  return 0;
}

static int field(const char *path, const char *tag, const char *key, double *out);

static int reorder_check(char **argv) {
  double stale, commands, pairs = atof(argv[3]);
  if (field(argv[2], "INTAKE", "stale", &stale) || field(argv[2], "INTAKE", "commands", &commands)) return 1;
  printf("server: %.0f commands applied, %.0f older ones skipped, of %.0f reordered pairs\n", commands, stale, pairs);
  /* Under heavy load the server's reader may drop a pair's samples from
   * its bounded history before the loop takes them (those are neither
   * applied nor counted): at least half the pairs must be seen reordered;
   * without the order check none is. */
  if (stale < 0.5 * pairs || stale > pairs) {
    fprintf(stderr, "FAIL: %.0f older commands skipped, expected one per pair (%.0f)\n", stale, pairs);
    return 1;
  }
  if (commands < 0.9 * pairs || commands > pairs) {
    fprintf(stderr, "FAIL: %.0f commands applied, expected the newer of each pair (%.0f)\n", commands, pairs);
    return 1;
  }
  return 0;
}

/* The value of `key=` on the first line of `path` starting with `tag`. */
static int field(const char *path, const char *tag, const char *key, double *out) {
  FILE *f = fopen(path, "r");
  char line[2048];
  int found = 0;
  if (!f) return -1;
  while (!found && fgets(line, sizeof line, f)) {
    if (strncmp(line, tag, strlen(tag)) != 0) continue;
    char pat[64];
    snprintf(pat, sizeof pat, " %s=", key);
    const char *p = strstr(line, pat);
    if (p) found = sscanf(p + strlen(pat), "%lf", out) == 1;
  }
  fclose(f);
  if (!found) fprintf(stderr, "flood_commands: no %s= on a %s line of %s\n", key, tag, path);
  return found ? 0 : -1;
}

static int check(int argc, char **argv) {
  if (argc != 5) return 2;
  const char *srv = argv[2], *hap = argv[3], *fl = argv[4];
  double range, refused, blocked, commands, overruns, steps, sim, ticks, new_ids, garbage, impostor, cpu_p99,
      cpu_median;
  if (field(srv, "INTAKE", "gate_out_of_range", &range) || field(srv, "INTAKE", "gate_refused", &refused) ||
      field(srv, "INTAKE", "gate_blocked", &blocked) || field(srv, "INTAKE", "commands", &commands) ||
      field(srv, "INTAKE", "overruns", &overruns) || field(srv, "INTAKE", "steps", &steps) ||
      field(srv, "INTAKE", "sim_time", &sim) || field(srv, "INTAKE", "step_cpu_us_p99", &cpu_p99) ||
      field(srv, "INTAKE", "step_cpu_us_median", &cpu_median) || field(hap, "SUMMARY", "ticks", &ticks) ||
      field(fl, "FLOOD", "sent_new_ids", &new_ids) || field(fl, "FLOOD", "sent_garbage", &garbage) ||
      field(fl, "FLOOD", "sent_impostor", &impostor))
    return 1;
  printf("server: %.0f steps, %.3f s simulated, %.0f overruns, step CPU p99 %.1f us, %.0f commands applied; gate: %.0f "
         "unknown ids, %.0f "
         "malformed, %.0f from the impostor; flood sent %.0f + %.0f + %.0f; owner sent %.0f\n",
         steps, sim, overruns, cpu_p99, commands, range, refused, blocked, new_ids, garbage, impostor, ticks);
  int bad = 0;
  /* Best effort may lose part of a flood on the way; what arrives is counted. */
  if (range < 0.2 * new_ids) bad = fprintf(stderr, "FAIL: unknown tool ids not dropped and counted at the gate\n");
  if (refused < 0.2 * garbage) bad = fprintf(stderr, "FAIL: garbage not dropped and counted at the gate\n");
  if (blocked < 0.2 * impostor) bad = fprintf(stderr, "FAIL: the impostor station was not blocked at the gate\n");
  if (commands < 0.75 * ticks)
    bad = fprintf(stderr, "FAIL: only %.0f of the owner's %.0f commands applied\n", commands, ticks);
  /* The 1 ms step, or 5 x the median for a sanitized build whose step
   * costs more without any flood. */
  if (cpu_p99 >= fmax(1000.0, 5 * cpu_median))
    bad = fprintf(stderr, "FAIL: the step's CPU time p99 %.1f us (median %.1f us) is above the step\n", cpu_p99,
                  cpu_median);
  return bad ? 1 : 0;
}

int main(int argc, char **argv) {
  int rc = 2;
  if (argc > 1 && strcmp(argv[1], "flood") == 0) rc = flood(argc, argv);
  if (argc > 1 && strcmp(argv[1], "check") == 0) rc = check(argc, argv);
  if (argc == 5 && strcmp(argv[1], "reorder") == 0) rc = reorder(argv);
  if (argc == 4 && strcmp(argv[1], "reorder-check") == 0) rc = reorder_check(argv);
  if (rc == 2)
    fprintf(stderr, "usage: flood_commands flood DOMAIN PARTITION PID[,PID...] COUNT SECONDS\n"
                    "       flood_commands check SERVER_OUT HAPTIC_OUT FLOOD_OUT\n"
                    "       flood_commands reorder DOMAIN PARTITION PAIRS\n"
                    "       flood_commands reorder-check SERVER_OUT PAIRS\n");
  return rc;
}
