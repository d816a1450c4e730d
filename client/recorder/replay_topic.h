/* SPDX-License-Identifier: Apache-2.0 */
/* replay_topic: a recorded topic set up for replay, with no compiled-in
 * type.
 *
 * For every topic of the recording the type descriptor is rebuilt from the
 * stored fields (size, align, flagset, keys, ops, type information and
 * mapping; recording.h), checked (a stored op count must be what Cyclone
 * counts in the stored program), the topic created with it and a writer
 * with the recorded QoS (transient and persistent durability become
 * transient-local; deadlines and leases stretch with a speed below 1). A
 * topic that cannot be set up is reported and left out; the others are
 * replayed. */
#ifndef VISCERA_REPLAY_TOPIC_H
#define VISCERA_REPLAY_TOPIC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata_default.h>
#include <sqlite3.h>

#include "verr.h"

typedef struct rp_topic {
  int64_t id;
  char name[256];
  char type_name[256];
  dds_topic_descriptor_t *desc;
  dds_key_descriptor_t *keys;
  uint32_t *ops;
  unsigned char *typeinfo, *typemap;
  struct ddsi_sertype_default st; /* only the descriptor part is used: for the cdrstream calls */
  ddsi_sertype_default_desc_key_t *st_keys;
  uint32_t nkeys; /* entries of keys filled (names owned) */
  dds_entity_t topic, writer;
  bool transient_local;
  uint64_t written, bad;
} rp_topic_t;

/* The outcome of one topic's stored type check (replay_typecheck.h). */
typedef struct rp_type_verdict {
  int64_t id; /* topics.id */
  int ok;     /* 1: the stored type information reads */
  char why[200];
} rp_type_verdict_t;

/* Where the topics come from and where they go. */
typedef struct rp_setup {
  sqlite3 *db;      /* the recording, read-only: the descriptor columns recfile does not expose */
  const char *path; /* its file name, for messages */
  dds_entity_t pp, pub;
  double speed;    /* --speed */
  size_t *refused; /* if not NULL: incremented per topic NOT replayed */
  /* From rp_types_precheck, made before the participant existed: the
   * check forks, and a child forked while Cyclone's threads run can
   * deadlock on a lock one of them held (seen: a 60 s hang under the
   * sanitizers on a loaded machine). NULL: checked here, forking now. */
  const rp_type_verdict_t *verdicts;
  size_t nverdicts;
} rp_setup_t;

/* Checks every topic's stored type information and mapping
 * (rp_types_check), each in a child process: call it before any DDS entity
 * (any thread) exists. *out: one verdict per topic row (caller frees).
 * -1 with err when the topic table is unreadable. */
int rp_types_precheck(sqlite3 *db, const char *path, rp_type_verdict_t **out, size_t *n, verr_t *err);

/* Sets up every topic of the recording that can be (the others are named
 * on stderr as NOT replayed) into *topics (*ntopics of them, the caller
 * frees each with rp_topic_free and then the array). -1 with err when the
 * topic table is unreadable or no topic could be set up. */
int rp_topics_setup(const rp_setup_t *r, rp_topic_t **topics, size_t *ntopics, verr_t *err);

/* Frees what the topic owns (not its DDS entities: deleted with the
 * participant). */
void rp_topic_free(rp_topic_t *t);

#endif
