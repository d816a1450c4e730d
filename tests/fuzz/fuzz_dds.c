/* SPDX-License-Identifier: Apache-2.0 */
/* fuzz_dds: throws mutated CDR at a running seat over DDS (issue 7, fault
 * tolerance: "a client sending garbage never crashes the server").
 *
 * Every sample starts from a corpus entry (tests/fuzz/corpus, files NAME.hex: the
 * topic name on the first line, the CDR bytes in hex after it) and gets 1-8
 * random mutations: bit flips, bytes set to 0x00/0x7f/0x80/0xff, a 4-byte
 * word replaced by a float NaN/Inf/huge/denormal or a huge count, bytes cut
 * off or appended. Cyclone validates serialised data against the type before
 * it leaves this process and again on arrival, so structurally broken bytes
 * are refused here (counted as "refused by DDS"); what passes is well formed
 * but semantically garbage (NaN poses, ids out of range, unknown enum
 * values, absurd sequence contents) and reaches the server and viewers,
 * whose own checks must hold. Deterministic for a given --seed.
 *
 * --make-corpus DIR writes the seed corpus from typed samples, valid and
 * deliberately bad, so the committed corpus can be regenerated. */
#include <dirent.h>
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include "cli.h"
#include "dds/vdds.h"
#include "replay_serdata.h"
#include "viscera.h"
#include "vtime.h"

#define MAX_ENTRIES 64
#define MAX_CDR 4096

typedef struct entry {
  vdds_topic_id_t topic;
  size_t len;
  uint8_t cdr[MAX_CDR];
} entry_t;

static uint64_t rng_state = 88172645463325252ull;
static uint64_t rnd(void) { /* xorshift64: tiny, deterministic, good enough to mutate bytes */
  rng_state ^= rng_state << 13;
  rng_state ^= rng_state >> 7;
  rng_state ^= rng_state << 17;
  return rng_state;
}

static int topic_by_name(const char *name) {
  for (int t = 0; t < VT_COUNT; t++)
    if (strcmp(vdds_topic_name((vdds_topic_id_t)t), name) == 0) return t;
  return -1;
}

static int write_hex(const char *dir, const char *name, vdds_topic_id_t topic, const uint8_t *b, size_t n) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s.hex", dir, name);
  FILE *f = fopen(path, "w");
  if (!f) return -1;
  fprintf(f, "%s\n", vdds_topic_name(topic));
  for (size_t i = 0; i < n; i++) fprintf(f, "%02x%s", b[i], (i % 32 == 31 || i + 1 == n) ? "\n" : "");
  return fclose(f);
}

/* The CDR of a typed sample: written by `writer` and taken raw by a reader
 * of the same participant (local delivery is immediate), which is how
 * Cyclone 0.10's public API gives serialised bytes without private calls. */
static int serialise(dds_entity_t writer, dds_entity_t reader, const void *sample, uint8_t *out, size_t *len) {
  if (dds_write(writer, sample) < 0) return -1;
  struct ddsi_serdata *sd = NULL;
  dds_sample_info_t info;
  for (int tries = 0; tries < 100; tries++) {
    int n = dds_takecdr(reader, &sd, 1, &info, DDS_ANY_STATE);
    if (n == 1) break;
    sd = NULL;
    dds_sleepfor(DDS_MSECS(10));
  }
  if (!sd) return -1;
  size_t n = ddsi_serdata_size(sd);
  int rc = -1;
  if (n <= MAX_CDR) {
    ddsi_serdata_to_ser(sd, 0, n, out);
    *len = n;
    rc = 0;
  }
  ddsi_serdata_unref(sd);
  return rc;
}

static int make_corpus(vdds_t *dds, const char *dir) {
  enum { N = 4 };
  static const vdds_topic_id_t ids[N] = {VT_TOOL_COMMAND, VT_SESSION_CONTROL, VT_MESH_STATE, VT_MESH_DELTA};
  dds_entity_t w[N], r[N];
  for (int i = 0; i < N; i++) {
    w[i] = vdds_writer(dds, ids[i], NULL);
    r[i] = vdds_reader(dds, ids[i], NULL);
    if (w[i] < 0 || r[i] < 0) return -1;
  }
  dds_entity_t w_cmd = w[0], w_ctl = w[1], w_state = w[2], w_delta = w[3];
  uint8_t buf[MAX_CDR];
  size_t n;
  int bad = 0;
  viscera_ToolCommand c = {.tool_id = 0,
                           .seq = 1,
                           .client_mono_ns = 1,
                           .position = {0.012f, 0.004f, 0.05f},
                           .orientation = {1, 0, 0, 0},
                           .max_force = 4};
  bad |= serialise(w_cmd, r[0], &c, buf, &n) || write_hex(dir, "toolcommand_valid", VT_TOOL_COMMAND, buf, n);
  c.position[2] = NAN;
  bad |= serialise(w_cmd, r[0], &c, buf, &n) || write_hex(dir, "toolcommand_nan", VT_TOOL_COMMAND, buf, n);
  c.position[2] = 0.05f;
  c.tool_id = 0xffffffffu;
  bad |= serialise(w_cmd, r[0], &c, buf, &n) || write_hex(dir, "toolcommand_bad_tool", VT_TOOL_COMMAND, buf, n);
  viscera_SessionControl s = {
      .source_id = 9, .seq = 1, .kind = viscera_CONTROL_SET_THRESHOLDS, .tool_id = 0, .values = {0.5, 0.8, 1.5, 0}};
  bad |= serialise(w_ctl, r[1], &s, buf, &n) || write_hex(dir, "sessioncontrol_thresholds", VT_SESSION_CONTROL, buf, n);
  /* A small valid keyframe and delta for organ 0: mutations of their
   * sequence lengths and indices exercise the viewers' bounds checks. */
  float pos[9] = {0, 0, 0, 0.01f, 0, 0, 0, 0.01f, 0};
  uint32_t tris[3] = {0, 1, 2}, idx[1] = {1};
  int16_t dq[3] = {10, -10, 5};
  viscera_MeshState m = {.organ_id = 0,
                         .positions = {._length = 9, ._maximum = 9, ._buffer = pos},
                         .triangles = {._length = 3, ._maximum = 3, ._buffer = tris}};
  bad |= serialise(w_state, r[2], &m, buf, &n) || write_hex(dir, "meshstate_small", VT_MESH_STATE, buf, n);
  viscera_MeshDelta d = {.organ_id = 0,
                         .quant_step = 1e-5f,
                         .indices = {._length = 1, ._maximum = 1, ._buffer = idx},
                         .dq = {._length = 3, ._maximum = 3, ._buffer = dq}};
  bad |= serialise(w_delta, r[3], &d, buf, &n) || write_hex(dir, "meshdelta_small", VT_MESH_DELTA, buf, n);
  return bad ? -1 : 0;
}

static int load_entry(const char *path, entry_t *e) {
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  char name[128];
  int ok = fgets(name, sizeof name, f) != NULL;
  if (ok) name[strcspn(name, "\r\n")] = 0;
  int t = ok ? topic_by_name(name) : -1;
  e->len = 0;
  int c, hi = -1;
  while (t >= 0 && (c = fgetc(f)) != EOF) {
    int v = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    if (v < 0) continue;
    if (hi < 0) {
      hi = v;
    } else if (e->len < MAX_CDR) {
      e->cdr[e->len++] = (uint8_t)(hi << 4 | v);
      hi = -1;
    }
  }
  fclose(f);
  if (t < 0 || e->len < 8) return -1;
  e->topic = (vdds_topic_id_t)t;
  return 0;
}

static void put32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); }

static size_t mutate(uint8_t *b, size_t len) {
  int n = 1 + (int)(rnd() % 8);
  for (int k = 0; k < n; k++) {
    /* Never touch the 4-byte encapsulation header: with it broken nothing
     * gets past the sender's own check, which tests nothing of ours. */
    size_t body = len > 4 ? len - 4 : 0;
    if (body == 0) break;
    size_t at = 4 + (size_t)(rnd() % body);
    switch (rnd() % 7) {
    case 0:
      b[at] ^= (uint8_t)(1u << (rnd() % 8));
      break;
    case 1: {
      static const uint8_t v[] = {0x00, 0x7f, 0x80, 0xff};
      b[at] = v[rnd() % 4];
      break;
    }
    case 2:
    case 3: {
      static const float fv[] = {NAN, INFINITY, -INFINITY, 3e38f, 1e-42f, -0.0f, 1e6f};
      at = 4 + ((at - 4) & ~(size_t)3);
      if (at + 4 <= len) {
        float f = fv[rnd() % 7];
        memcpy(b + at, &f, 4);
      }
      break;
    }
    case 4: {
      static const uint32_t uv[] = {0xffffffffu, 0x7fffffffu, 0x10000u, 3, 0};
      at = 4 + ((at - 4) & ~(size_t)3);
      if (at + 4 <= len) put32(b + at, uv[rnd() % 5]);
      break;
    }
    case 5:
      len = 4 + (size_t)(rnd() % body);
      break; /* cut */
    case 6:  /* append */
      for (int i = 0; i < 8 && len < MAX_CDR; i++) b[len++] = (uint8_t)rnd();
      break;
    }
  }
  return len;
}

static void usage(FILE *f) {
  fprintf(f, "usage: fuzz_dds --corpus DIR [--samples N] [--seconds S] [--seed N] [--partition P] [--domain N]\n"
             "       fuzz_dds --make-corpus DIR\n");
}

int main(int argc, char **argv) {
  vdds_set_role("fuzz"); /* announced in the participant USER_DATA */
  static const struct option opts[] = {{"corpus", required_argument, 0, 'c'},
                                       {"make-corpus", required_argument, 0, 'm'},
                                       {"samples", required_argument, 0, 'n'},
                                       {"seconds", required_argument, 0, 's'},
                                       {"seed", required_argument, 0, 'r'},
                                       {"partition", required_argument, 0, 'p'},
                                       {"domain", required_argument, 0, 'd'},
                                       {"help", no_argument, 0, 'h'},
                                       {0, 0, 0, 0}};
  const char *corpus = NULL, *make = NULL, *partition = NULL;
  long samples = 20000;
  double seconds = 5;
  verr_t err;
  int domain = cli_env_domain(&err), c;
  while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
    switch (c) {
    case 'c':
      corpus = optarg;
      break;
    case 'm':
      make = optarg;
      break;
    case 'n':
      samples = atol(optarg);
      break;
    case 's':
      seconds = atof(optarg);
      break;
    case 'r':
      rng_state = strtoull(optarg, NULL, 10) | 1;
      break;
    case 'p':
      partition = optarg;
      break;
    case 'd':
      domain = cli_parse_domain(optarg);
      break;
    case 'h':
      usage(stdout);
      return 0;
    default:
      usage(stderr);
      return 2;
    }
  }
  if ((!corpus == !make) || domain < 0 || samples <= 0 || !(seconds > 0)) {
    usage(stderr);
    return 2;
  }
  vdds_t dds;
  if (vdds_open(&dds, domain, partition, &err)) {
    fprintf(stderr, "fuzz_dds: %s\n", err.msg);
    return 1;
  }
  int rc = 0;
  if (make) {
    rc = make_corpus(&dds, make) ? 1 : 0;
    if (rc) fprintf(stderr, "fuzz_dds: cannot write the corpus to %s\n", make);
    vdds_close(&dds);
    return rc;
  }
  static entry_t entries[MAX_ENTRIES];
  size_t nentries = 0;
  DIR *d = opendir(corpus);
  struct dirent *de;
  while (d && (de = readdir(d)) && nentries < MAX_ENTRIES) {
    size_t l = strlen(de->d_name);
    if (l < 5 || strcmp(de->d_name + l - 4, ".hex")) continue;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", corpus, de->d_name);
    if (load_entry(path, &entries[nentries]) == 0)
      nentries++;
    else
      fprintf(stderr, "fuzz_dds: %s: not a corpus entry (topic name line, then hex bytes), skipped\n", path);
  }
  if (d) closedir(d);
  if (nentries == 0) {
    fprintf(stderr, "fuzz_dds: no corpus entries in %s\n", corpus);
    vdds_close(&dds);
    return 1;
  }
  dds_entity_t writers[VT_COUNT] = {0};
  for (size_t i = 0; i < nentries; i++) {
    vdds_topic_id_t t = entries[i].topic;
    if (!writers[t] && (writers[t] = vdds_writer(&dds, t, &err)) < 0) {
      fprintf(stderr, "fuzz_dds: %s\n", err.msg);
      vdds_close(&dds);
      return 1;
    }
  }
  dds_sleepfor(DDS_MSECS(500)); /* let the writers match, or the first samples reach nobody */
  uint64_t sent = 0, refused = 0, per_topic[VT_COUNT] = {0};
  uint64_t t0 = vtime_mono_ns();
  uint8_t buf[MAX_CDR];
  for (long i = 0; i < samples; i++) {
    const entry_t *e = &entries[rnd() % nentries];
    memcpy(buf, e->cdr, e->len);
    size_t len = mutate(buf, e->len);
    if (replay_serdata_forward(writers[e->topic], buf, len, false, RSD_DATA, dds_time()) == DDS_RETCODE_OK) {
      sent++;
      per_topic[e->topic]++;
    } else {
      refused++;
    }
    /* Spread the samples over the duration: a flood at memory speed would
     * test the transport, not the checks. */
    uint64_t due = t0 + (uint64_t)((double)(i + 1) / (double)samples * seconds * 1e9);
    vtime_sleep_until(due);
  }
  printf("fuzz_dds: %" PRIu64 " mutated samples delivered, %" PRIu64 " refused by DDS's own type check", sent, refused);
  for (int t = 0; t < VT_COUNT; t++)
    if (per_topic[t]) printf("; %s %" PRIu64, vdds_topic_name((vdds_topic_id_t)t), per_topic[t]);
  printf("\n");
  dds_sleepfor(DDS_MSECS(300));
  vdds_close(&dds);
  return rc;
}
