/* SPDX-License-Identifier: Apache-2.0 */
#include "session/server.h"

#include <inttypes.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <unistd.h>

#include "mesh.h"
#include "runtime/region_work.h"
#include "runtime/rollback_report.h"
#include "runtime/step_cut.h"
#include "session/applied_input.h"
#include "session/checkpoint.h"
#include "session/scene_source.h"
#include "session/command_intake.h"
#include "session/liveliness_watch.h"
#include "session/session_control.h"
#include "session/session_tool.h"
#include "session/tool_metrics.h"
#include "session/tool_roles.h"
#include "session/writer_stations.h"
#include "sha256.h"
#include "dds/vdds_gate.h"
#include "dds/vdds_subject.h"
#include "viscera.h"
#include "vmath.h"
#include "vrt.h"
#include "vstats.h"
#include "vtime.h"

#define STEP_RING 65536

struct server {
  const server_opts_t *opts;
  const char *tag; /* what the log lines start with: opts->log_tag or "server" */
  runtime_t rt;
  vdds_t dds;
  dds_entity_t w_scene, w_state, w_delta, w_feedback, w_event, w_metrics, r_cmd, r_control;
  /* Set by the SessionControl reader's listener (a DDS thread) when data
   * arrives, cleared by the step that takes it: instructor commands are
   * rare, and a take from the empty reader every step cost 1 us warm and
   * 4.6 us when the other seats' processes had emptied the caches
   * (docs/numerics.md §11). 1 at start: anything already there is taken. */
  atomic_int control_pending;
  dds_entity_t w_chunk;   /* keyframes in single-datagram chunks (dds/key_chunks.h) */
  uint32_t chunk_readers; /* readers of w_chunk matched so far (total_count) */
  dds_entity_t w_objects, w_tool_metrics, w_role, w_applied, w_source;
  mesh_publisher_t pubs[SCENE_MAX_ORGANS];
  /* Each tool's session record (session_tool.h: measures, intake,
   * feedback), by its index in the core's rt.tools. */
  session_tool_t tool[SCENE_MAX_TOOLS];
  /* Loss detection: the writers driving each tool are in roles (per side). */
  liveliness_watch_t lw;
  /* Who drives each tool and each side's latest command (tool_roles.h);
   * the station of each command writer (writer_stations.h). */
  tool_roles_t roles;
  writer_stations_t stations;
  /* The ToolCommand reader's gate (dds/vdds_gate.h): only the scene's tools,
   * only well-formed commands, and no writer once its station was refused
   * for a tool, ever reach the reader's cache; the counters seen so far. */
  vdds_gate_t cmd_gate;
  command_gate_t cmd_check;
  uint64_t gate_seen[VDDS_GATE_REASONS], gate_seen_range, gate_seen_blocked;
  session_control_t control;
  rollback_report_t rb; /* rolled-back steps: reported at most once per simulated second */
  /* What each loop iteration applied, for the recording (applied_input.h). */
  applied_input_t ai;
  uint64_t event_seq;
  uint64_t feedback_seq;              /* ContactFeedback.seq of the last sample written */
  tool_rt_t preview[SCENE_MAX_TOOLS]; /* the step's feedback preview (publish_feedback_early) */
  double *step_us;                    /* ring of recent step times */
  double *step_cpu_us;                /* the same steps' thread CPU times */
  unsigned char *step_awake;          /* the same steps: 1 when an organ was stepped (not all asleep, not paused) */
  double *step_tissue_us;             /* the same steps: thread CPU inside the runtime's step (contact and organs) */
  uint64_t tissue_ns;                 /* the current step's, summed over runtime_step_begin and _finish */
  /* The current step's thread CPU and wall time, summed over its phases
   * (server_step_begin, _tissue, _end): with several sessions on one
   * thread (seat_group.h) the other sessions' phases run in between. */
  uint64_t step_cpu_ns, step_wall_ns;
  uint32_t early;       /* tools answered before the tissue step (publish_feedback_early) */
  int rolled;           /* the tissue step's rolled-back organs */
  uint64_t started_ns;  /* monotonic time of the first step (0 before): the real-time ratio's start */
  uint64_t last_end_ns; /* the end of the last step's publishing: the ratio's end */
  double sim0;          /* simulated time at the first step (a resumed run starts at its checkpoint's) */
  checkpointer_t *ckpt;
  uint64_t ckpt_every; /* steps between checkpoints */
  char resumed[300];   /* "resumed from checkpoint ..." or empty */
  size_t nstep_us;
  uint64_t publish_every, metrics_every; /* steps between frames, between metrics */
  server_stats_t *stats;
  /* A resumed session: the state it resumed from and the checkpoint file's
   * digest, recorded in SceneSource (checkpoint_resume_state). */
  state_blob_t resume;
  char resume_sha256[SHA256_HEX_LEN];
};

static uint64_t sim_ns(const server_t *s) { return (uint64_t)(s->rt.sim_time * 1e9); }

/* task: the scene's task index the event is about, -1 for none (its name
 * goes with it, so a reader pairs a task's events by id, not by text). */
static void publish_task_event(server_t *s, viscera_EventKind kind, int organ, int tool, double value, const char *text,
                               int task) {
  viscera_SessionEvent e;
  memset(&e, 0, sizeof e);
  e.source_id = 0;
  e.seq = ++s->event_seq;
  e.sim_time_ns = sim_ns(s);
  e.kind = kind;
  e.organ_id = organ;
  e.tool_id = tool;
  e.value = value;
  snprintf(e.text, sizeof e.text, "%s", text);
  e.task_id = task;
  if (task >= 0 && (size_t)task < s->rt.scene.ntasks)
    snprintf(e.task_name, sizeof e.task_name, "%s", s->rt.scene.tasks[task].name);
  if (dds_write(s->w_event, &e) >= 0) s->stats->published[VT_SESSION_EVENT]++;
}

static void publish_event(server_t *s, viscera_EventKind kind, int organ, int tool, double value, const char *text) {
  publish_task_event(s, kind, organ, tool, value, text, -1);
}

static void publish_scene_info(server_t *s) {
  const scene_t *sc = &s->rt.scene;
  viscera_SceneInfo si;
  memset(&si, 0, sizeof si);
  viscera_OrganInfo organs[SCENE_MAX_ORGANS];
  viscera_ToolInfo tools[SCENE_MAX_TOOLS];
  memset(organs, 0, sizeof organs);
  memset(tools, 0, sizeof tools);
  snprintf(si.scene, sizeof si.scene, "%s", sc->name);
  snprintf(si.description, sizeof si.description, "%s", sc->description);
  si.physics_dt = sc->dt;
  si.publish_hz = sc->publish_hz;
  si.quant_step = (float)sc->quant_step;
  for (size_t i = 0; i < s->rt.norgans; i++) {
    const organ_rt_t *o = &s->rt.organs[i];
    organs[i].organ_id = o->id;
    snprintf(organs[i].name, sizeof organs[i].name, "%s", o->cfg->name);
    snprintf(organs[i].model, sizeof organs[i].model, "%s", o->cfg->model);
    snprintf(organs[i].integrator, sizeof organs[i].integrator, "%s", o->cfg->integrator);
    organs[i].vertex_count = (uint32_t)o->model->nsurf;
    organs[i].triangle_count = (uint32_t)o->model->nsurf_tris;
    memcpy(organs[i].color, o->cfg->color, sizeof organs[i].color);
  }
  for (size_t t = 0; t < s->rt.ntools; t++) {
    const scene_tool_t *c = s->rt.tools[t].cfg;
    tools[t].tool_id = (uint32_t)t;
    snprintf(tools[t].name, sizeof tools[t].name, "%s", c->name);
    snprintf(tools[t].kind, sizeof tools[t].kind, "%s", c->kind);
    tools[t].radius = (float)c->radius;
    tools[t].length = (float)c->length;
    tools[t].stiffness = (float)c->stiffness;
    tools[t].max_force = (float)c->max_force;
    /* The levels in force: the scene's, or an instructor's SET_THRESHOLDS
     * (dashboards and viewers draw and judge by these). */
    const thr_tracker_t *tr = &s->tool[t].thr;
    tools[t].st = (float)tr->level[THR_ST];
    tools[t].mpf = (float)tr->level[THR_MPF];
    tools[t].sft = (float)tr->level[THR_SFT];
  }
  si.organs._buffer = organs;
  si.organs._length = si.organs._maximum = (uint32_t)s->rt.norgans;
  si.tools._buffer = tools;
  si.tools._length = si.tools._maximum = (uint32_t)s->rt.ntools;
  if (dds_write(s->w_scene, &si) >= 0) s->stats->published[VT_SCENE_INFO]++;
}

/* The scene's text, mesh digests and the build (scene_source.h), once. */
static void publish_scene_source(server_t *s) {
  viscera_SceneSource src;
  verr_t e;
  if (scene_source_fill(&src, &s->rt.scene, NULL, &e)) fprintf(stderr, "%s: warning: %s\n", s->tag, e.msg);
  /* borrowed for the write only */
  src.resume_state._buffer = s->resume.p;
  src.resume_state._length = src.resume_state._maximum = (uint32_t)s->resume.len;
  snprintf(src.resume_sha256, sizeof src.resume_sha256, "%s", s->resume_sha256);
  if (dds_write(s->w_source, &src) >= 0) s->stats->published[VT_SCENE_SOURCE]++;
  src.resume_state._buffer = NULL;
  src.resume_state._length = src.resume_state._maximum = 0;
  scene_source_free(&src);
}

/* The ToolCommand reader, behind the intake gate. Its topic keeps the last
 * sample per tool, but two writers share a tool when it is guided
 * (tool_roles.h): with depth 1 one station's sample would overwrite the
 * other's before the loop takes it. 32 per tool covers both at 1 kHz
 * through a 16 ms stall of the loop; writers of other stations, garbage and
 * unknown tools never take a place (the gate). At most one instance per
 * scene tool. */
#define CMD_READER_DEPTH 32
static dds_entity_t command_reader(server_t *s, const dds_listener_t *l, verr_t *err) {
  s->cmd_check.ntools = s->rt.ntools;
  s->cmd_check.workspace = s->rt.workspace;
  s->cmd_gate.key_bound = (uint32_t)s->rt.ntools; /* before the reader exists: no receive thread reads it yet */
  int ntools = s->rt.ntools > 0 ? (int)s->rt.ntools : 1;
  return vdds_reader_gated(&s->dds, VT_TOOL_COMMAND, &s->cmd_gate, CMD_READER_DEPTH, ntools, l, err);
}

/* SessionControl instances are per instructor station number, which any
 * participant may mint: bounded, like every keyed reader (issue 15.1). */
#define CONTROL_MAX_STATIONS 64
static void on_control_data(dds_entity_t reader, void *arg) {
  (void)reader;
  atomic_store((atomic_int *)arg, 1);
}

static dds_entity_t control_reader(server_t *s, verr_t *err) {
  dds_qos_t *q = vdds_topic_qos(VT_SESSION_CONTROL);
  dds_qset_resource_limits(q, DDS_LENGTH_UNLIMITED, CONTROL_MAX_STATIONS, DDS_LENGTH_UNLIMITED);
  atomic_init(&s->control_pending, 1);
  dds_listener_t *l = dds_create_listener(&s->control_pending);
  dds_lset_data_available(l, on_control_data);
  dds_entity_t r = dds_create_reader(s->dds.subscriber, s->dds.topics[VT_SESSION_CONTROL], q, l);
  dds_delete_listener(l);
  dds_delete_qos(q);
  if (r < 0) verr_set(err, "DDS: cannot create the SessionControl reader: %s", dds_strretcode(r));
  return r;
}

/* A writer or reader the permissions refused (DDS_RETCODE_NOT_ALLOWED_BY_SECURITY,
 * the message of err): names the identity and the
 * partition, the usual cause being an identity of another seat (or a
 * group identity without this seat, deploy/pki.sh --server-group).
 * Returns -1. */
static int security_hint(const server_t *s, verr_t *err) {
  uint8_t der[VDDS_SUBJECT_DER_MAX];
  char who[VDDS_SUBJECT_TEXT_MAX] = "";
  size_t n = vdds_subject_self(der);
  if (!n || vdds_subject_text(der, n, who, sizeof who) < 0) return -1;
  char msg[VERR_MSG_LEN];
  snprintf(msg, sizeof msg, "%s", err->msg);
  return verr_set(err,
                  "%s: identity '%s' may not serve partition '%s' (deploy/pki.sh: server-seatNN serves its seat, "
                  "server-seatKK-MM seats K..M)",
                  msg, who, s->opts->partition ? s->opts->partition : "");
}

/* The session's participant, writers and readers (under opts->dds_setup_lock
 * when given). Returns 0, or -1 with err. */
static int setup_dds(server_t *s, verr_t *err) {
  if (vdds_open(&s->dds, s->opts->domain, s->opts->partition, err)) return -1;
  s->w_scene = vdds_writer(&s->dds, VT_SCENE_INFO, err);
  s->w_state = vdds_writer(&s->dds, VT_MESH_STATE, err);
  s->w_delta = vdds_writer(&s->dds, VT_MESH_DELTA, err);
  s->w_feedback = vdds_writer(&s->dds, VT_CONTACT_FEEDBACK, err);
  s->w_event = vdds_writer(&s->dds, VT_SESSION_EVENT, err);
  s->w_metrics = vdds_writer(&s->dds, VT_METRICS, err);
  dds_listener_t *l = dds_create_listener(&s->lw);
  liveliness_watch_listen(&s->lw, l);
  s->r_cmd = command_reader(s, l, err);
  dds_delete_listener(l);
  s->r_control = control_reader(s, err);
  s->w_objects = vdds_writer(&s->dds, VT_OBJECT_STATE, err);
  s->w_tool_metrics = vdds_writer(&s->dds, VT_TOOL_METRICS, err);
  s->w_role = vdds_writer(&s->dds, VT_TOOL_ROLE, err);
  s->w_applied = vdds_writer(&s->dds, VT_APPLIED_INPUT, err);
  s->w_source = vdds_writer(&s->dds, VT_SCENE_SOURCE, err);
  const dds_entity_t needed[] = {s->w_scene,   s->w_state,   s->w_delta,   s->w_feedback, s->w_event,
                                 s->w_metrics, s->r_cmd,     s->r_control, s->w_objects,  s->w_tool_metrics,
                                 s->w_role,    s->w_applied, s->w_source};
  for (size_t k = 0; k < sizeof needed / sizeof needed[0]; k++)
    if (needed[k] < 0) return needed[k] == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY ? security_hint(s, err) : -1;
  s->w_chunk = vdds_writer(&s->dds, VT_MESH_KEY_CHUNK, err);
  if (s->w_chunk < 0) {
    /* Permissions made by an older deploy/pki.sh do not grant this topic:
     * keyframes then go as MeshState only (slower over a lossy link). */
    fprintf(stderr, "%s: keyframe chunks off (%s); keyframes go as MeshState only\n", s->tag, err->msg);
    s->w_chunk = 0;
  }
  return 0;
}

static int setup(server_t *s, const scene_t *scene, verr_t *err) {
  liveliness_watch_init(&s->lw); /* first: teardown always destroys them */
  vdds_gate_init(&s->cmd_gate, 0, command_gate_check, &s->cmd_check);
  rollback_report_init(&s->rb, (uint64_t)fmax(1.0, floor(1.0 / scene->dt + 0.5)));
  if (runtime_init(&s->rt, scene, err)) return -1;
  if (s->opts->dds_setup_lock) pthread_mutex_lock(s->opts->dds_setup_lock);
  int rc = setup_dds(s, err);
  if (s->opts->dds_setup_lock) pthread_mutex_unlock(s->opts->dds_setup_lock);
  if (rc) return -1;
  tool_roles_init(&s->roles, &s->rt.scene);
  s->roles.playout_depth = s->opts->command_playout;
  writer_stations_init(&s->stations);
  s->control.roles = &s->roles;
  applied_input_init(&s->ai, s->w_applied, &s->rt, &s->control.paused);
  /* The samples go out from a thread of their own (applied_outbox.h). */
  s->ai.outbox = applied_outbox_start(s->w_applied, APPLIED_OUTBOX_PERIOD_NS, err);
  if (!s->ai.outbox) return -1;
  for (size_t i = 0; i < s->rt.norgans; i++) {
    organ_rt_t *o = &s->rt.organs[i];
    if (mesh_publisher_init(&s->pubs[i], o->id, o->model->nsurf, o->model->surf_tris, o->model->nsurf_tris,
                            (float)scene->quant_step, s->w_state, s->w_delta, err))
      return -1;
    s->pubs[i].keepalive_ns = (uint64_t)(scene->publish_keepalive * 1e9);
    s->pubs[i].w_chunk = s->w_chunk;
    /* Benchmarks only: two copies of each chunk, to compare (dds/key_chunks.h). */
    const char *copies = getenv("VISCERA_KEY_CHUNK_COPIES");
    s->pubs[i].chunk_copies = copies && !strcmp(copies, "2") ? 2 : 0;
  }
  s->step_us = calloc(STEP_RING, sizeof(double));
  s->step_cpu_us = calloc(STEP_RING, sizeof(double));
  s->step_awake = calloc(STEP_RING, 1);
  s->step_tissue_us = calloc(STEP_RING, sizeof(double));
  if (!s->step_us || !s->step_cpu_us || !s->step_awake || !s->step_tissue_us) return verr_set(err, "out of memory");
  return 0;
}

/* Writes what the outbox still holds and stops its thread; its counts join
 * applied_input's. Before the writer goes (vdds_close). */
static void stop_applied_outbox(server_t *s) {
  uint64_t published = 0, failed = 0;
  applied_outbox_stop(s->ai.outbox, &published, &failed);
  s->ai.outbox = NULL;
  s->ai.published += published;
  s->ai.failed += failed;
}

static void teardown(server_t *s) {
  stop_applied_outbox(s);
  free(s->resume.p);
  for (size_t i = 0; i < s->rt.norgans; i++) mesh_publisher_destroy(&s->pubs[i]);
  runtime_destroy(&s->rt);
  if (s->opts->dds_setup_lock) pthread_mutex_lock(s->opts->dds_setup_lock); /* not beside another's setup_dds */
  vdds_close(&s->dds); /* stops the listener before the watch goes */
  if (s->opts->dds_setup_lock) pthread_mutex_unlock(s->opts->dds_setup_lock);
  liveliness_watch_destroy(&s->lw);
  vdds_gate_destroy(&s->cmd_gate);
  free(s->step_us);
  free(s->step_cpu_us);
  free(s->step_awake);
  free(s->step_tissue_us);
}

/* Releases every tool whose commanding writer lost its liveliness (the
 * client process died): at the next step instead of after the command
 * timeout. */
static void release_lost_writers(server_t *s, uint64_t now) {
  liveliness_lost_t e;
  while (liveliness_watch_pop(&s->lw, now, LIVELINESS_CONFIRM_NS, &e)) {
    for (size_t t = 0; t < s->rt.ntools; t++) {
      int side = tool_roles_side_of_writer(&s->roles, t, e.writer);
      if (!s->rt.tools[t].active || side < 0) continue;
      uint64_t last = s->roles.tool[t].side[side].mono_ns;
      if (e.expired && (e.regained || last > e.mono_ns)) {
        /* Alive after all: this process was starved past the lease (see
         * liveliness_watch.h). Keep the tool; say so a few times. */
        if (++s->stats->liveliness_blips <= 3 && !s->opts->quiet)
          fprintf(stderr,
                  "%s: tool %zu: client liveliness lapsed while it kept sending (machine overloaded?); "
                  "kept\n",
                  s->tag, t);
        continue;
      }
      /* One side of a guided tool gone: its hand stops counting at once and
       * the other side drives alone (tool_roles.h); the tool stays, so no
       * CLIENT_LOST (which says the tool was released, e.g. to viscera-resim). */
      char who[TOOL_ROLE_STATION_MAX + 16];
      const char *st = s->roles.tool[t].side[side].station;
      snprintf(who, sizeof who, st[0] ? "station '%s'" : "anonymous%s", st);
      tool_roles_forget(&s->roles, t, (tool_side_t)side);
      tool_effective_t eff;
      /* A guide never takes the tool away with it; the owner's loss
       * releases it unless the guide is driving right now. */
      if (side == TOOL_SIDE_GUIDE || tool_roles_effective(&s->roles, t, now, &eff)) {
        if (!s->opts->quiet)
          fprintf(stderr, "%s: tool %zu: %s client (%s) lost: the %s drives on alone\n", s->tag, t,
                  side ? "guide" : "owner", who, side ? "owner" : "guide");
        continue;
      }
      runtime_release_tool(&s->rt, t);
      applied_input_release(&s->ai, t);
      s->tool[t].lost = 1;
      /* From the last command taken to the listener's report, and to this
       * release (which adds the confirmation delay and the step). */
      double heard_ms = e.mono_ns > last ? (double)(e.mono_ns - last) * 1e-6 : 0;
      double released_ms = (double)(now - last) * 1e-6;
      char text[200];
      if (e.expired)
        snprintf(text, sizeof text,
                 "haptic client lost (liveliness lost %.0f ms after its last command, lease %d ms; released at "
                 "%.0f ms): tool released",
                 heard_ms, VDDS_TOOL_LEASE_MS, released_ms);
      else
        snprintf(text, sizeof text, "haptic client left (its command writer was deleted): tool released");
      if (!s->opts->quiet) fprintf(stderr, "%s: tool %zu: %s\n", s->tag, t, text);
      publish_event(s, viscera_EVENT_CLIENT_LOST, -1, (int)t, (double)(now - last) * 1e-9, text);
    }
  }
}

/* Moves tool t to the pose its stations give it now (tool_roles.h: the
 * owner's, the guide's, or their mix). */
static void drive_tool(server_t *s, size_t t, uint64_t now) {
  tool_effective_t eff;
  if (!tool_roles_effective(&s->roles, t, now, &eff)) return;
  if (s->tool[t].lost) {
    s->tool[t].lost = 0;
    if (!s->opts->quiet) fprintf(stderr, "%s: tool %zu: haptic client back\n", s->tag, t);
  }
  const double *was = s->rt.tools[t].cmd.pos;
  double d[3] = {eff.cmd.pos[0] - was[0], eff.cmd.pos[1] - was[1], eff.cmd.pos[2] - was[2]};
  s->tool[t].jumped = s->rt.tools[t].active && v3_norm(d) > SESSION_EARLY_JUMP_M;
  runtime_command_tool(&s->rt, t, &eff.cmd);
  applied_input_command(&s->ai, t, &eff.cmd);
}

/* Publishes the ToolRole of every tool whose role changed (or all, after
 * start and after a reset). */
static void publish_roles(server_t *s) {
  uint32_t changed = s->roles.changed;
  s->roles.changed = 0;
  for (size_t t = 0; t < s->roles.ntools; t++) {
    if (!(changed & (1u << t))) continue;
    viscera_ToolRole m;
    tool_roles_fill(&s->roles, t, sim_ns(s), &m);
    if (dds_write(s->w_role, &m) >= 0) s->stats->published[VT_TOOL_ROLE]++;
  }
}

/* One rejected ToolCommand: counted, and reported for the first few and
 * then every 1000th, so a flood of garbage cannot flood the event topic or
 * the log. */
static void report_rejected(server_t *s, tool_cmd_verdict_t v, uint32_t tool, const char *station, const char *how) {
  s->stats->rejected[v]++;
  uint64_t r = ++s->stats->rejected_total;
  if (r > 5 && r % 1000 != 0) return;
  char text[200], who[64];
  if (v == TOOLCMD_NOT_ASSIGNED)
    snprintf(text, sizeof text,
             "ToolCommand for tool %u from %s rejected%s: tool assigned to station '%s' (%" PRIu64 " rejected so far)",
             tool, station[0] ? tool_roles_who(station, who, sizeof who) : "an anonymous station", how,
             tool < s->roles.ntools ? s->roles.tool[tool].owner : "?", r);
  else
    snprintf(text, sizeof text, "ToolCommand from tool %u rejected%s: %s (%" PRIu64 " rejected so far)", tool, how,
             tool_command_verdict_str(v), r);
  if (!s->opts->quiet) fprintf(stderr, "%s: %s\n", s->tag, text);
  publish_event(s, viscera_EVENT_INPUT_REJECTED, -1, (int)(tool < 1u << 30 ? tool : 0), (double)r, text);
}

/* Counts what the intake gate dropped since the last step as rejected
 * commands (the gate keeps them out of the reader: vdds_gate.h). */
static void count_gate_drops(server_t *s) {
  vdds_gate_t *g = &s->cmd_gate;
  uint32_t key = atomic_load(&g->last_refused_key);
  uint64_t range = atomic_load(&g->out_of_range), blocked = atomic_load(&g->from_blocked);
  for (; s->gate_seen_range < range; s->gate_seen_range++) report_rejected(s, TOOLCMD_BAD_ID, key, "", " at intake");
  for (int v = 1; v < VDDS_GATE_REASONS && v < TOOLCMD_VERDICT_COUNT; v++)
    for (uint64_t n = atomic_load(&g->reason[v]); s->gate_seen[v] < n; s->gate_seen[v]++)
      report_rejected(s, (tool_cmd_verdict_t)v, key, "", " at intake");
  for (; s->gate_seen_blocked < blocked; s->gate_seen_blocked++) {
    s->stats->rejected[TOOLCMD_NOT_ASSIGNED]++;
    s->stats->rejected_total++;
  }
  s->stats->gate_out_of_range = range;
  s->stats->gate_refused = atomic_load(&g->refused);
  s->stats->gate_blocked = blocked;
}

/* Takes every pending ToolCommand from DDS as the core's command
 * (command_intake.h), checks it (tool_command_check) and its station
 * (tool_roles_classify), and keeps a valid one as its side's latest
 * (tool_roles_note) unless its writer already gave that side a newer one
 * (seq: best effort may deliver out of order; issue 14.2); counts and
 * reports the rest. A writer whose station may not drive the tool is
 * blocked at the gate for that tool, so its flood cannot evict the
 * owner's commands from the reader. */
static void take_commands(server_t *s, uint64_t now) {
  enum { MAXS = 16 };
  void *samples[MAXS] = {0};
  dds_sample_info_t infos[MAXS];
  count_gate_drops(s);
  for (;;) {
    int n = dds_take(s->r_cmd, samples, infos, MAXS, MAXS);
    if (n <= 0) break;
    for (int i = 0; i < n; i++) {
      if (!infos[i].valid_data) continue;
      const viscera_ToolCommand *c = samples[i];
      tool_cmd_t cmd;
      command_from_dds(c, &cmd);
      tool_cmd_verdict_t v = tool_command_check(&cmd, s->rt.ntools, &s->rt.workspace);
      const char *station = "";
      tool_side_t side = TOOL_SIDE_REJECTED;
      if (v == TOOLCMD_OK) { /* well-formed: does its station drive this tool? */
        station = writer_stations_get(&s->stations, s->r_cmd, infos[i].publication_handle);
        side = tool_roles_classify(&s->roles, c->tool_id, station);
        if (side == TOOL_SIDE_REJECTED) {
          v = TOOLCMD_NOT_ASSIGNED;
          vdds_gate_block(&s->cmd_gate, infos[i].publication_handle, c->tool_id);
        }
      }
      if (v != TOOLCMD_OK) {
        report_rejected(s, v, c->tool_id, station, "");
        continue;
      }
      if (tool_roles_stale(&s->roles, c->tool_id, side, infos[i].publication_handle, cmd.seq)) {
        s->stats->commands_stale++; /* older than what this writer already gave: never applied after it */
        continue;
      }
      tool_roles_note(&s->roles, c->tool_id, side, station, infos[i].publication_handle, &cmd, now);
      s->tool[c->tool_id].last_cmd_mono = now;
      s->stats->commands++;
    }
    dds_return_loan(s->r_cmd, samples, n);
    if (n < MAXS) break;
  }
}

/* Releases every driven tool whose client is gone: its writer lost its
 * liveliness (release_lost_writers) or it sent nothing for tool_timeout. */
static void release_lost_tools(server_t *s, uint64_t now) {
  release_lost_writers(s, now);
  for (size_t t = 0; t < s->rt.ntools; t++) {
    if (s->rt.tools[t].active && now - s->tool[t].last_cmd_mono > (uint64_t)(s->opts->tool_timeout * 1e9)) {
      runtime_release_tool(&s->rt, t);
      applied_input_release(&s->ai, t);
      s->tool[t].lost = 1;
      if (!s->opts->quiet)
        fprintf(stderr, "%s: tool %zu: no commands for %.1f s, released\n", s->tag, t, s->opts->tool_timeout);
      publish_event(s, viscera_EVENT_CLIENT_LOST, -1, (int)t, s->opts->tool_timeout,
                    "haptic client lost (no commands): tool released");
    }
  }
}

/* Applies pending instructor commands (session_control.h); each outcome is
 * logged and published, so the recording shows who changed what and when. */
/* Restarts the scene from `sc` (a reset, or a reset with new material):
 * the runtime is rebuilt (models, trees, proxies, tools released, tasks and
 * stones back), measures restart, and every organ's publisher adopts the
 * new surface with a keyframe of a new topology version, so viewers and
 * late joiners follow as after a cut. When `sc` cannot be built (a material
 * the models refuse) the running scene `old` is rebuilt instead and -1
 * returned with err; if even that fails the server cannot go on (-2). */
static int rebuild_runtime(server_t *s, const scene_t *sc, const scene_t *old, verr_t *err) {
  runtime_destroy(&s->rt);
  int rc = 0;
  if (runtime_init(&s->rt, sc, err)) {
    verr_t e2;
    runtime_destroy(&s->rt);
    if (runtime_init(&s->rt, old, &e2)) {
      fprintf(stderr, "%s: cannot rebuild the scene after a refused change: %s\n", s->tag, e2.msg);
      return -2;
    }
    rc = -1;
  }
  for (size_t t = 0; t < s->rt.ntools; t++) {
    const scene_tool_t *c = s->rt.tools[t].cfg;
    thr_init(&s->tool[t].thr, c->st, c->mpf, c->sft);
    memset(&s->tool[t].tally, 0, sizeof s->tool[t].tally);
    s->tool[t].was_contact = 0;
  }
  tool_roles_forget_all(&s->roles); /* tools released; roles kept and published again */
  for (size_t i = 0; i < s->rt.norgans; i++) {
    const organ_rt_t *o = &s->rt.organs[i];
    const model_t *m = o->model;
    verr_t e;
    if (mesh_publisher_retopo(&s->pubs[i], o->topology_version, m->nsurf, m->surf_tris, m->nsurf_tris, m->surf_x,
                              sim_ns(s), &e))
      fprintf(stderr, "%s: %s\n", s->tag, e.msg);
  }
  return rc;
}

/* An instructor's START_TASK (session_control.h): the task (re)starts now,
 * reported as a TASK_STARTED whose text carries the station tag. */
static void start_task(server_t *s, int k, const char *text) {
  tasks_start(&s->rt.tasks[k], s->rt.sim_time);
  publish_task_event(s, viscera_EVENT_TASK_STARTED, -1, s->rt.scene.tasks[k].tool, 1, text, k);
}

/* Applies pending instructor commands (session_control.h); each outcome is
 * logged and published, so the recording shows who changed what and when. */
static int read_controls(server_t *s) {
  void *samples[1] = {0};
  dds_sample_info_t info;
  /* Cleared before the take: a sample arriving after it sets it again. */
  if (!atomic_exchange(&s->control_pending, 0)) return 0;
  while (dds_take(s->r_control, samples, &info, 1, 1) == 1) {
    if (info.valid_data && !session_control_duplicate(&s->control, samples[0])) {
      const viscera_SessionControl *c = samples[0];
      double maxf[SCENE_MAX_TOOLS];
      for (size_t t = 0; t < s->rt.ntools; t++) maxf[t] = s->rt.tools[t].cfg->max_force;
      char text[300];
      /* The scene lives in the runtime, which a rebuild destroys: work on
       * copies (heap: a scene is tens of kB). */
      scene_t *edit = malloc(sizeof *edit), *old = malloc(sizeof *old);
      int r = -1, result = -1, task = -1;
      applied_input_begin_control(&s->ai); /* the state before any rebuild */
      if (edit && old) {
        *edit = s->rt.scene;
        *old = s->rt.scene;
        r = session_control_apply(&s->control, c, s->tool, s->rt.ntools, maxf, edit, text, sizeof text);
      } else {
        snprintf(text, sizeof text, "SessionControl refused: out of memory");
      }
      if (r == SESSION_CONTROL_REBUILD) {
        verr_t e;
        int b = rebuild_runtime(s, edit, old, &e);
        applied_input_rebuilt(&s->ai);
        result = b == 0 ? 1 : 2;
        if (b == -2) {
          free(edit);
          free(old);
          dds_return_loan(s->r_control, samples, 1);
          return -1;
        }
        if (b == 0) {
          s->control.applied++;
          r = 0;
          /* A stiff material is accepted as in a scene file, but the
           * instructor should know when the step may no longer keep time. */
          for (size_t i = 0; i < s->rt.norgans; i++) {
            const model_t *m = s->rt.organs[i].model;
            size_t len = strlen(text);
            if (m->substeps > 16 && len < sizeof text)
              snprintf(text + len, sizeof text - len,
                       "; organ '%.40s' now needs %d sub-steps per step (may not keep real time)",
                       s->rt.organs[i].cfg->name, m->substeps);
          }
        } else {
          s->control.refused++;
          size_t len = strlen(text);
          snprintf(text + len, sizeof text - len, "; refused by the models: %.200s (scene unchanged, restarted)",
                   e.msg);
        }
      }
      if (r == SESSION_CONTROL_START_TASK) {
        r = 0;
        task = s->control.start_task;
        start_task(s, task, text);
      }
      if (r == 0 && result < 0) result = 0;
      applied_input_control(&s->ai, c, result, task);
      free(edit);
      free(old);
      if (!s->opts->quiet) fprintf(stderr, "%s: %s\n", s->tag, text);
      /* New levels, or the scene's again after a rebuild: SceneInfo
       * (transient-local) carries the levels in force, also to late joiners. */
      if ((r == 0 && c->kind == viscera_CONTROL_SET_THRESHOLDS) || result == 1 || result == 2) publish_scene_info(s);
      publish_event(s, r == 0 ? viscera_EVENT_CONTROL_APPLIED : viscera_EVENT_INPUT_REJECTED, c->organ_id, c->tool_id,
                    (double)c->kind, text);
    }
    dds_return_loan(s->r_control, samples, 1);
  }
  return 0;
}

/* One ContactFeedback of tool t from the record `tool` (the core's, or the
 * preview's copy), stamped with the simulated time now. Its `force` is
 * always the core's: the hand force the server committed at that instant
 * (for an early answer, the previous step's, whose end is this step's
 * start), the one its own measures track, so a report rebuilt from the
 * recorded feedback equals the server's PALPATION figures; the preview
 * moves only the contact model the client renders (god-object, normal,
 * contact). */
static void write_feedback(server_t *s, size_t t, const tool_rt_t *tool) {
  const tool_rt_t *core = &s->rt.tools[t];
  viscera_ContactFeedback fb;
  memset(&fb, 0, sizeof fb);
  fb.tool_id = (uint32_t)t;
  fb.cmd_seq = tool->cmd.seq;
  fb.cmd_client_mono_ns = tool->cmd.echo;
  fb.sim_time_ns = sim_ns(s);
  fb.seq = ++s->feedback_seq;
  /* fb_*: the god-object, or what a grasp, a stone or another tool
   * makes the hand feel (runtime/step_tools.c). */
  fb.in_contact = tool->fb_contact != 0;
  fb.organ_id = tool->fb_contact ? tool->fb_organ : -1;
  fb.stiffness = (float)tool->cfg->stiffness;
  for (int k = 0; k < 3; k++) {
    fb.proxy_position[k] = (float)tool->fb_pos[k];
    fb.normal[k] = (float)tool->fb_normal[k];
    fb.force[k] = (float)core->force[k];
  }
  if (dds_write(s->w_feedback, &fb) >= 0) s->stats->published[VT_CONTACT_FEEDBACK]++;
}

/* Before the tissue step (issue 17): every driven tool with a fresh command
 * (bit t of `fresh`) is answered at once from the preview (its god-object
 * moved over the surfaces as they are; runtime_feedback_preview), stamped
 * with the step's start time, unless its command jumped (session_tool.h:
 * SESSION_EARLY_JUMP_M; it is answered after the step, publish_feedback).
 * Returns the tools answered. */
static uint32_t publish_feedback_early(server_t *s, uint32_t fresh) {
  uint32_t done = 0;
  for (size_t t = 0; t < s->rt.ntools; t++)
    if ((fresh & (1u << t)) && s->rt.tools[t].active && !s->tool[t].jumped) done |= 1u << t;
  if (!done) return 0;
  runtime_feedback_preview(&s->rt, s->preview);
  for (size_t t = 0; t < s->rt.ntools; t++)
    if (done & (1u << t)) write_feedback(s, t, &s->preview[t]);
  return done;
}

/* After the step: the ContactFeedback of every driven tool not answered
 * before it (`early`), from the core record; the contact begin/end events
 * of every tool from the core record, as the step left it. */
static void publish_feedback(server_t *s, uint32_t early) {
  for (size_t t = 0; t < s->rt.ntools; t++) {
    const tool_rt_t *tool = &s->rt.tools[t];
    if (!tool->active) continue;
    if (!(early & (1u << t))) write_feedback(s, t, tool);
    int c = tool->fb_contact != 0;
    if (c != s->tool[t].was_contact) {
      publish_event(s, c ? viscera_EVENT_CONTACT_BEGIN : viscera_EVENT_CONTACT_END, c ? tool->fb_organ : -1, (int)t, 0,
                    c ? "contact begins" : "contact ends");
      s->tool[t].was_contact = c;
    }
  }
}

/* Feeds every tool's contact force and tip to its threshold tracker and
 * publishes the crossings. */
static void track_thresholds(server_t *s) {
  for (size_t t = 0; t < s->rt.ntools; t++) {
    const tool_rt_t *tool = &s->rt.tools[t];
    double f = tool->active ? v3_norm(tool->force) : 0.0;
    int contact = tool->active && tool->fb_contact;
    thr_event_t ev[THR_COUNT];
    int n = thr_update(&s->tool[t].thr, s->rt.scene.dt, f, contact, tool->active ? tool->cmd.pos : NULL, ev);
    for (int i = 0; i < n; i++) {
      char text[200];
      snprintf(text, sizeof text, "%s %s: tool '%s' force %.3f N %s %.3f N", thr_name(ev[i].which),
               ev[i].up ? "crossed up" : "crossed down", tool->cfg->name, f, ev[i].up ? "above" : "back below",
               ev[i].level);
      if (!s->opts->quiet) fprintf(stderr, "%s: %s\n", s->tag, text);
      publish_event(s, ev[i].up ? viscera_EVENT_THRESHOLD_CROSSED_UP : viscera_EVENT_THRESHOLD_CROSSED_DOWN,
                    contact ? tool->fb_organ : -1, (int)t, ev[i].level, text);
    }
  }
}

/* The recent steps that stepped an organ: what a step of physics costs,
 * without the near-free steps of sleeping organs diluting the median. */
static void summarise_awake(const server_t *s, size_t n, server_stats_t *stats) {
  double *w = malloc((n + 1) * sizeof *w), *c = malloc((n + 1) * sizeof *c);
  size_t k = 0;
  if (w && c)
    for (size_t i = 0; i < n; i++)
      if (s->step_awake[i]) {
        w[k] = s->step_us[i];
        c[k++] = s->step_cpu_us[i];
      }
  vstats_summary_t sw = vstats_summarise(w, k), sc = vstats_summarise(c, k);
  stats->awake_samples = k;
  stats->awake_step_us_median = sw.median;
  stats->awake_step_us_p99 = sw.p99;
  stats->awake_step_cpu_us_median = sc.median;
  stats->awake_step_cpu_us_p99 = sc.p99;
  free(w);
  free(c);
}

static void publish_metrics(server_t *s, uint64_t window_steps) {
  size_t n = s->nstep_us < STEP_RING ? s->nstep_us : STEP_RING;
  size_t take = window_steps < n ? window_steps : n;
  double *tmp = malloc((take + 1) * sizeof(double));
  if (!tmp) return;
  for (size_t i = 0; i < take; i++) tmp[i] = s->step_us[(s->nstep_us - 1 - i) % STEP_RING];
  vstats_summary_t st = vstats_summarise(tmp, take);
  free(tmp);
  double peak = 0;
  for (size_t t = 0; t < s->rt.ntools; t++) peak = fmax(peak, s->rt.tools[t].peak_force);
  double above[THR_COUNT] = {0}, contact = 0, fint = 0, path = 0;
  for (size_t t = 0; t < s->rt.ntools; t++) {
    const thr_tracker_t *tr = &s->tool[t].thr;
    for (int k = 0; k < THR_COUNT; k++) above[k] += tr->time_above[k];
    contact += tr->contact_time;
    fint += tr->contact_force_integral;
    path += tr->path_length;
  }
  for (size_t i = 0; i < s->rt.norgans; i++) {
    viscera_Metrics m;
    memset(&m, 0, sizeof m);
    m.organ_id = s->rt.organs[i].id;
    m.sim_time_ns = sim_ns(s);
    m.step_time_us_median = st.median;
    m.step_time_us_p99 = st.p99;
    m.steps_per_s = (double)take;
    const model_t *model = s->rt.organs[i].model;
    m.error_estimate = model->ops->error_estimate(model);
    snprintf(m.error_kind, sizeof m.error_kind, "%s", model->error_kind ? model->error_kind : "");
    m.peak_force = peak;
    m.rejected_commands = s->stats->rejected_total;
    m.time_above_st = above[THR_ST];
    m.time_above_mpf = above[THR_MPF];
    m.time_above_sft = above[THR_SFT];
    m.contact_time = contact;
    m.mean_contact_force = contact > 0 ? fint / contact : 0.0;
    m.path_length = path;
    if (dds_write(s->w_metrics, &m) >= 0) s->stats->published[VT_METRICS]++;
  }
}

/* Grasp and task events from the runtime's queue, as SessionEvents. */
static void publish_interactions(server_t *s) {
  const scene_t *sc = &s->rt.scene;
  for (size_t i = 0; i < s->rt.events.n; i++) {
    const iev_t *e = &s->rt.events.ev[i];
    const char *tool = e->tool >= 0 ? sc->tools[e->tool].name : "?";
    char text[200];
    viscera_EventKind kind = viscera_EVENT_GRASP_BEGIN;
    switch (e->kind) {
    case IEV_GRASP_BEGIN:
    case IEV_GRASP_END:
      kind = e->kind == IEV_GRASP_BEGIN ? viscera_EVENT_GRASP_BEGIN : viscera_EVENT_GRASP_END;
      if (e->object >= 0)
        snprintf(text, sizeof text, "tool '%s' %s stone '%s'", tool, e->kind == IEV_GRASP_BEGIN ? "grasps" : "releases",
                 sc->objects[e->object].name);
      else
        snprintf(text, sizeof text, "tool '%s' %s organ '%s'%s", tool,
                 e->kind == IEV_GRASP_BEGIN ? "grasps" : "releases", e->organ >= 0 ? sc->organs[e->organ].name : "?",
                 e->kind == IEV_GRASP_BEGIN ? " tissue" : "");
      break;
    case IEV_TASK_STARTED:
      kind = viscera_EVENT_TASK_STARTED;
      snprintf(text, sizeof text, "task '%s' started (tool '%s')", sc->tasks[e->task].name, tool);
      break;
    case IEV_TASK_COMPLETED:
      kind = viscera_EVENT_TASK_COMPLETED;
      snprintf(text, sizeof text, "task '%s' completed in %.3f s (tool '%s')", sc->tasks[e->task].name, e->value, tool);
      break;
    case IEV_CUT_BEGIN:
      kind = viscera_EVENT_CUT_BEGIN;
      snprintf(text, sizeof text, "tool '%s' cuts organ '%s' (%.0f surface vertices)", tool, sc->organs[e->organ].name,
               e->value);
      break;
    case IEV_CUT_END: {
      kind = viscera_EVENT_CUT_END;
      const model_t *m = s->rt.organs[e->organ].model;
      double wmean = 0, wmax = 0;
      size_t nw = scalpel_incision_width(&s->rt, (size_t)e->organ, &wmean, &wmax);
      int k = snprintf(text, sizeof text, "tool '%s' ends its cut of organ '%s': %.0f topology change(s), %zu vertices",
                       tool, sc->organs[e->organ].name, e->value, m->nsurf);
      if (nw && k > 0 && (size_t)k < sizeof text)
        snprintf(text + k, sizeof text - (size_t)k, ", incision width %.2f mm mean, %.2f mm max", wmean * 1e3,
                 wmax * 1e3);
      break;
    }
    }
    if (!s->opts->quiet) fprintf(stderr, "%s: %s\n", s->tag, text);
    bool about_task = e->kind == IEV_TASK_STARTED || e->kind == IEV_TASK_COMPLETED;
    publish_task_event(s, kind, e->organ, e->tool, e->value, text, about_task ? e->task : -1);
  }
  s->rt.events.n = 0;
  /* A refused cut is logged (the first few, then every 100th), never fatal. */
  char msg[240];
  uint64_t r = scalpel_take_error(&s->rt, msg, sizeof msg);
  if (r && (r <= 5 || r % 100 == 0) && !s->opts->quiet)
    fprintf(stderr, "%s: %s (%" PRIu64 " refused so far)\n", s->tag, msg, r);
}

static void publish_objects(server_t *s) {
  for (size_t i = 0; i < s->rt.nstones; i++) {
    const stone_t *st = &s->rt.stones[i];
    const scene_object_t *c = &s->rt.scene.objects[i];
    viscera_ObjectState o;
    memset(&o, 0, sizeof o);
    o.object_id = (uint32_t)i;
    o.sim_time_ns = sim_ns(s);
    snprintf(o.name, sizeof o.name, "%s", c->name);
    snprintf(o.kind, sizeof o.kind, "%s", c->kind);
    for (int k = 0; k < 3; k++) {
      o.position[k] = (float)st->pos[k];
      o.color[k] = c->color[k];
    }
    o.radius = (float)st->radius;
    o.organ_id = st->organ;
    o.held_by = st->held_by;
    o.removed = st->removed != 0;
    dds_write(s->w_objects, &o);
  }
}

static void publish_tool_metrics(server_t *s) {
  for (size_t t = 0; t < s->rt.ntools; t++) {
    viscera_ToolMetrics m;
    tool_metrics_fill(&m, &s->rt, t, &s->tool[t].thr, &s->tool[t].tally, sim_ns(s));
    dds_write(s->w_tool_metrics, &m);
  }
}

/* A reader of the keyframe chunks matched since the last frame (a late
 * joiner): the current keyframes go to it as new samples, one way
 * (mesh_publisher_rechunk). */
static void rechunk_for_new_readers(server_t *s) {
  dds_publication_matched_status_t st;
  if (!s->w_chunk || dds_get_publication_matched_status(s->w_chunk, &st) < 0 || st.total_count == s->chunk_readers)
    return;
  s->chunk_readers = st.total_count;
  for (size_t i = 0; i < s->rt.norgans; i++) mesh_publisher_rechunk(&s->pubs[i]);
}

static void publish_frames(server_t *s) {
  publish_objects(s);
  rechunk_for_new_readers(s);
  for (size_t i = 0; i < s->rt.norgans; i++)
    mesh_publisher_frame(&s->pubs[i], s->rt.organs[i].model->surf_x, sim_ns(s));
}

/* An organ whose runtime rebuilt for a new topology (topology_follow.h)
 * gets a keyframe of its new surface at once and a SessionEvent. */
static void follow_topology(server_t *s) {
  for (size_t i = 0; i < s->rt.norgans; i++) {
    const organ_rt_t *o = &s->rt.organs[i];
    mesh_publisher_t *mp = &s->pubs[i];
    if (o->topology_version == mp->model_version || mp->broken) continue;
    const model_t *m = o->model;
    verr_t e;
    char text[200];
    if (mesh_publisher_retopo(mp, o->topology_version, m->nsurf, m->surf_tris, m->nsurf_tris, m->surf_x, sim_ns(s),
                              &e)) {
      fprintf(stderr, "%s: %s\n", s->tag, e.msg);
      continue;
    }
    snprintf(text, sizeof text, "organ '%s': topology %u: %zu vertices, %zu triangles", o->cfg->name,
             mp->topology_version, m->nsurf, m->nsurf_tris);
    if (!s->opts->quiet && mp->retopos <= 5) fprintf(stderr, "%s: %s\n", s->tag, text);
    publish_event(s, viscera_EVENT_TOPOLOGY_CHANGED, (int)i, -1, (double)m->nsurf, text);
  }
}

static void write_final_mesh(server_t *s) {
  /* Exact positions of the last published frame, so a test can compare a
   * viewer's reconstruction with the server's state at the same frame. */
  for (size_t i = 0; i < s->rt.norgans; i++) {
    char path[1100];
    if (s->rt.norgans == 1)
      snprintf(path, sizeof path, "%s", s->opts->final_mesh);
    else
      snprintf(path, sizeof path, "%s.%zu", s->opts->final_mesh, i);
    const model_t *model = s->rt.organs[i].model;
    mesh_t m = {
        .nverts = model->nsurf, .ntris = model->nsurf_tris, .pos = model->surf_x, .tris = (uint32_t *)model->surf_tris};
    char comment[160];
    snprintf(comment, sizeof comment, "organ %zu topology %u keyframe %u frame %u", i, s->pubs[i].topology_version,
             s->pubs[i].keyframe_seq, s->pubs[i].frame_seq);
    verr_t e;
    if (mesh_write_obj(&m, path, comment, &e)) fprintf(stderr, "%s: %s\n", s->tag, e.msg);
  }
}

/* Resident set of this process in kB (0 when /proc is not there). */
static long rss_kb(void) {
  FILE *f = fopen("/proc/self/statm", "r");
  long pages = 0, resident = 0;
  if (!f) return 0;
  if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
  fclose(f);
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

/* The step's wall and CPU time, summed over its phases (the step-time rings). */
static void record_step_time(server_t *s) {
  s->step_cpu_us[s->nstep_us % STEP_RING] = (double)s->step_cpu_ns * 1e-3;
  s->step_tissue_us[s->nstep_us % STEP_RING] = (double)s->tissue_ns * 1e-3;
  int awake = !s->control.paused && s->rt.organs_stepped > 0;
  s->step_awake[s->nstep_us % STEP_RING] = (unsigned char)awake;
  if (!s->control.paused && !awake) s->stats->steps_all_asleep++;
  if (awake) {
    s->stats->awake_steps++;
    s->stats->awake_tissue_ns += s->tissue_ns;
  }
  s->step_us[s->nstep_us++ % STEP_RING] = (double)s->step_wall_ns * 1e-3;
}

/* Rolled-back steps (runtime_step): an event and a log line at most once
 * per simulated second, counting the ones held back (rollback_report.h);
 * an organ put back to rest after a run of them is always said. */
static void report_rollbacks(server_t *s, int rolled) {
  s->stats->rollbacks += (uint64_t)rolled;
  uint64_t n = 0;
  if (rollback_report_note(&s->rb, s->rt.steps, rolled, &n)) {
    char text[160];
    snprintf(text, sizeof text, "non-finite state: %" PRIu64 " organ step(s) rolled back since the last report", n);
    publish_event(s, viscera_EVENT_STEP_ROLLED_BACK, -1, -1, (double)n, text);
    if (!s->opts->quiet) fprintf(stderr, "%s: step %" PRIu64 ": %s\n", s->tag, s->rt.steps, text);
  }
  for (size_t i = 0; i < s->rt.norgans; i++) {
    if (!(s->rt.organs_reset & (1u << i))) continue;
    char text[200];
    snprintf(text, sizeof text,
             "organ '%.60s' reset to rest after %d consecutive rolled-back steps (%" PRIu64 " so far)",
             s->rt.organs[i].cfg->name, RUNTIME_ROLLBACK_RESET, s->rt.organs[i].rest_resets);
    publish_event(s, viscera_EVENT_STEP_ROLLED_BACK, (int)i, -1, RUNTIME_ROLLBACK_RESET, text);
    fprintf(stderr, "%s: step %" PRIu64 ": %s\n", s->tag, s->rt.steps, text);
  }
}

/* One step of the session, started at t0 (monotonic ns; c0 the thread's
 * CPU time then): the walk of a ToolCommand from the DDS take to the
 * ContactFeedback write. t1 is when the step's work was done (before the
 * metrics). -1 when the scene could not be rebuilt after a control. */
/* server.h: the first phase of a step. */
int server_step_begin(server_t *s, uint64_t t0) {
  uint64_t c0 = vtime_thread_cpu_ns();
  if (!s->started_ns) s->started_ns = t0;
  s->step_cpu_ns = 0;
  s->step_wall_ns = 0;
  s->tissue_ns = 0;
  s->early = 0;
  s->rolled = 0;
  /* In: take and convert the commands, check them, note each side's latest. */
  applied_input_tick(&s->ai);
  take_commands(s, t0);
  /* Once per step, after every side's commands are in: each side puts its
   * next waiting command into effect (command_playout.h: one per step, so
   * a tool moves evenly however its commands bunched on the way), and each
   * tool whose command changed takes its effective command (owner, guide or
   * their mix) into its core record. */
  uint32_t fresh = tool_roles_advance(&s->roles);
  for (size_t t = 0; t < s->rt.ntools; t++)
    if (fresh & (1u << t)) drive_tool(s, t, t0);
  release_lost_tools(s, t0);
  if (read_controls(s)) return -1;
  if (s->roles.changed) {
    /* A changed role may let a refused station in: it is judged afresh. */
    for (size_t t = 0; t < s->roles.ntools; t++)
      if (s->roles.changed & (1u << t)) vdds_gate_unblock_key(&s->cmd_gate, (uint32_t)t);
    publish_roles(s);
  }
  /* Step: paused, the organs and the measures freeze; commands are still
   * read (so nothing queues up) and the last contact model keeps going out.
   * A tool with a fresh command is answered between the step's contact
   * phase and its tissue step (runtime_step_begin/finish: the same step as
   * runtime_step), so its ContactFeedback does not wait for the organs.
   * The runtime's share of the step's CPU (its contact phase and organs)
   * is kept apart from the messages around it (stats: step_tissue_cpu). */
  if (!s->control.paused) {
    uint64_t b0 = vtime_thread_cpu_ns();
    runtime_step_begin(&s->rt);
    s->tissue_ns = vtime_thread_cpu_ns() - b0;
    s->early = publish_feedback_early(s, fresh);
  }
  /* Before the tissue step it precedes (after the early answers, which
   * wait for nothing; the sample's content was fixed at the take). */
  applied_input_flush(&s->ai);
  s->step_cpu_ns += vtime_thread_cpu_ns() - c0;
  s->step_wall_ns += vtime_mono_ns() - t0;
  return 0;
}

/* server.h: the tissue step. */
void server_step_tissue(server_t *s) {
  if (s->control.paused) return;
  uint64_t w0 = vtime_mono_ns(), f0 = vtime_thread_cpu_ns();
  s->rolled = runtime_step_finish(&s->rt);
  uint64_t d = vtime_thread_cpu_ns() - f0;
  s->tissue_ns += d;
  s->step_cpu_ns += d;
  s->step_wall_ns += vtime_mono_ns() - w0;
}

/* server.h: the step's messages out. */
uint64_t server_step_end(server_t *s) {
  uint64_t w0 = vtime_mono_ns(), c0 = vtime_thread_cpu_ns();
  if (s->rolled) report_rollbacks(s, s->rolled);
  /* Out: keyframes after a topology change, the ContactFeedback of every
   * driven tool not answered before the step (its force, tip and normal
   * from the core record), the trainee measures, the step's events, frames
   * and metrics. */
  follow_topology(s);
  publish_feedback(s, s->early);
  if (!s->control.paused) {
    track_thresholds(s);
    for (size_t t = 0; t < s->rt.ntools; t++) tool_tally_update(&s->tool[t].tally, &s->rt.tools[t], s->rt.scene.dt);
    publish_interactions(s); /* the events of the step just taken */
  }
  if (s->rt.steps % s->publish_every == 0) publish_frames(s);
  uint64_t t1 = vtime_mono_ns();
  s->step_cpu_ns += vtime_thread_cpu_ns() - c0;
  s->step_wall_ns += t1 - w0;
  s->last_end_ns = t1;
  record_step_time(s);
  if (s->rt.steps % s->metrics_every == 0) {
    long kb = rss_kb();
    if (!s->stats->rss_start_kb) s->stats->rss_start_kb = kb;
    if (kb > s->stats->rss_max_kb) s->stats->rss_max_kb = kb;
    publish_metrics(s, s->metrics_every);
    publish_tool_metrics(s);
  }
  if (s->ckpt && s->rt.steps % s->ckpt_every == 0) checkpointer_submit(s->ckpt, &s->rt, s->tool, &s->roles);
  return t1;
}

uint64_t server_dt_ns(const server_t *s) { return (uint64_t)(s->rt.scene.dt * 1e9); }

void server_note_overrun(server_t *s) { s->stats->overruns++; }

/* Logs what each organ runs (not with opts->quiet). */
static void log_organs(const server_t *s, const scene_t *scene) {
  const server_opts_t *opts = s->opts;
  for (size_t i = 0; i < s->rt.norgans; i++) {
    const organ_rt_t *o = &s->rt.organs[i];
    const model_t *m = o->model;
    fprintf(stderr,
            "%s: organ '%s': %s, %s, %zu nodes, %zu tetrahedra, surface %zu vertices / %zu triangles, "
            "%d sub-step(s) per %.3g ms (stable below %.3g ms)\n",
            s->tag, o->cfg->name, m->ops->name, o->cfg->integrator, m->nnodes, m->ntets, m->nsurf, m->nsurf_tris,
            m->substeps, scene->dt * 1e3, m->stable_dt * 1e3);
    if (o->mesh_note[0]) fprintf(stderr, "%s: organ '%s': mesh repaired: %s\n", s->tag, o->cfg->name, o->mesh_note);
    if (m->substeps > 0 && scene->dt / m->substeps > m->stable_dt)
      fprintf(stderr,
              "%s: organ '%s': warning: solver.substeps %d gives %.3g ms sub-steps, above the "
              "stable %.3g ms: expect rollbacks\n",
              s->tag, o->cfg->name, m->substeps, scene->dt / m->substeps * 1e3, m->stable_dt * 1e3);
  }
  fprintf(stderr, "%s: scene '%s' running on domain %d, partition '%s'\n", s->tag, scene->name, opts->domain,
          opts->partition ? opts->partition : VDDS_DEFAULT_PARTITION);
}

/* Resumes from opts->checkpoint when it fits and starts the checkpointer.
 * Returns 0, or -1 with err (the session cannot run). */
static int open_checkpoint(server_t *s, verr_t *err) {
  const server_opts_t *opts = s->opts;
  server_stats_t *stats = s->stats;
  verr_t e;
  /* the digest of the file as it is loaded: the checkpointer rewrites it later */
  uint64_t ckpt_size = 0;
  if (sha256_file(opts->checkpoint, s->resume_sha256, &ckpt_size, &e)) s->resume_sha256[0] = 0;
  int r = checkpoint_load(opts->checkpoint, &s->rt, s->tool, &s->roles, &e);
  if (r == -2) return verr_set(err, "%s (cannot rebuild the scene after it)", e.msg);
  if (r < 0) {
    fprintf(stderr, "%s: %s\n", s->tag, e.msg);
    /* A topology restore that failed midway rebuilt the runtime: the
     * publishers must drop the old models' surfaces they borrow. */
    for (size_t i = 0; i < s->rt.norgans; i++) {
      const model_t *m = s->rt.organs[i].model;
      if (s->pubs[i].tris != m->surf_tris &&
          mesh_publisher_retopo(&s->pubs[i], s->rt.organs[i].topology_version, m->nsurf, m->surf_tris, m->nsurf_tris,
                                m->surf_x, 0, &e))
        fprintf(stderr, "%s: %s\n", s->tag, e.msg);
    }
  } else if (r == 1) {
    stats->resumed = 1;
    snprintf(s->resumed, sizeof s->resumed, "resumed from checkpoint %s at t = %.3f s (step %llu)", opts->checkpoint,
             s->rt.sim_time, (unsigned long long)s->rt.steps);
    if (!opts->quiet) fprintf(stderr, "%s: %s\n", s->tag, s->resumed);
    follow_topology(s); /* a restored cut: keyframes of its topology before anything else */
    if (checkpoint_resume_state(&s->resume, &s->rt, s->tool, &e) || s->resume.bad) {
      /* the session runs on; its recording cannot be re-simulated */
      fprintf(stderr, "%s: warning: the resumed state cannot be recorded: %s\n", s->tag,
              s->resume.bad ? "out of memory" : e.msg);
      free(s->resume.p);
      s->resume = (state_blob_t){0};
    }
  }
  if (r != 1) s->resume_sha256[0] = 0; /* from rest: nothing resumed */
  return (s->ckpt = checkpointer_start(opts->checkpoint, err)) ? 0 : -1;
}

server_t *server_open(const scene_t *scene, const server_opts_t *opts, server_stats_t *stats, verr_t *err) {
  server_t *s = calloc(1, sizeof *s);
  memset(stats, 0, sizeof *stats);
  if (!s) {
    verr_set(err, "out of memory for a session");
    return NULL;
  }
  s->opts = opts;
  s->tag = opts->log_tag ? opts->log_tag : "server";
  s->stats = stats;
  if (setup(s, scene, err)) {
    teardown(s);
    free(s);
    return NULL;
  }
  if (!opts->quiet) log_organs(s, scene);
  for (size_t t = 0; t < s->rt.ntools; t++) {
    const scene_tool_t *c = s->rt.tools[t].cfg;
    thr_init(&s->tool[t].thr, c->st, c->mpf, c->sft);
  }
  if (opts->checkpoint && open_checkpoint(s, err)) {
    teardown(s);
    free(s);
    return NULL;
  }
  s->ckpt_every = (uint64_t)fmax(1.0, floor(opts->checkpoint_every / scene->dt + 0.5));
  publish_scene_info(s);
  publish_scene_source(s);
  publish_roles(s);
  /* Stamped with the simulated time of the state: 0 from rest, the
   * checkpoint's when resumed (a re-simulation matches frames by step). */
  for (size_t i = 0; i < s->rt.norgans; i++)
    mesh_publisher_keyframe(&s->pubs[i], s->rt.organs[i].model->surf_x, sim_ns(s));
  publish_event(s, viscera_EVENT_SESSION_STARTED, -1, -1, stats->resumed, s->resumed[0] ? s->resumed : scene->name);
  s->publish_every = (uint64_t)fmax(1.0, floor(1.0 / (scene->publish_hz * scene->dt) + 0.5));
  s->metrics_every = (uint64_t)fmax(1.0, floor(1.0 / scene->dt + 0.5));
  s->sim0 = s->rt.sim_time; /* a resumed run starts where its checkpoint was */
  return s;
}

void server_thread_prepare(const server_opts_t *opts, const char *tag) {
  /* Real time for the calling thread only, after every other thread (DDS,
   * the checkpoint writer) has started, so they stay SCHED_OTHER. The loop
   * sleeps to each tick in vtime_sleep_until, so FIFO costs the machine no
   * more CPU than the steps; but a loop whose steps take longer than dt
   * never sleeps (it catches up, resynchronising when 100 ms behind) and
   * would hold its core for good. The kernel's RT throttling
   * (sched_rt_runtime_us: 950 ms of every second by default) is the safety
   * net that still lets the other tasks (this server's DDS threads, a shell
   * to stop it) run there. */
  if (opts->physics_cpus) {
    char why[160];
    if (cpu_pin_self(opts->physics_cpus, why, sizeof why))
      fprintf(stderr, "%s: warning: --physics-cpus refused: %s; the physics loop runs where the scheduler puts it\n",
              tag, why);
    else if (!opts->quiet)
      fprintf(stderr, "%s: physics loop kept on CPUs %s\n", tag, opts->physics_cpus->text);
  }
  if (opts->rt_priority) vrt_make_realtime(opts->rt_priority, tag, "physics loop", opts->quiet, stderr);
  /* A SCHED_OTHER loop wakes up to the thread's timer slack (50 us by
   * default) after each tick: every command would wait that much longer
   * for its step and its answer (issue 17 item 5). 1 ns: on time. */
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
}

void server_close(server_t *s) {
  const server_opts_t *opts = s->opts;
  const scene_t *scene = &s->rt.scene;
  server_stats_t *stats = s->stats;
  publish_frames(s);
  publish_metrics(s, s->metrics_every);
  publish_tool_metrics(s);
  if (s->ckpt) {
    checkpointer_submit(s->ckpt, &s->rt, s->tool, &s->roles);
    verr_t e;
    if (checkpointer_stop(s->ckpt, &stats->checkpoints_written, &e)) fprintf(stderr, "%s: %s\n", s->tag, e.msg);
  }
  if (opts->final_mesh) write_final_mesh(s);
  publish_event(s, viscera_EVENT_SESSION_STOPPED, -1, -1, 0, scene->name);

  stats->steps = s->rt.steps;
  applied_input_flush(&s->ai);
  stop_applied_outbox(s);
  stats->published[VT_APPLIED_INPUT] = s->ai.published;
  for (size_t i = 0; i < s->rt.norgans; i++) {
    stats->published[VT_MESH_STATE] += s->pubs[i].keyframes;
    stats->published[VT_MESH_KEY_CHUNK] += s->pubs[i].chunk_samples;
    stats->published[VT_MESH_DELTA] += s->pubs[i].frames;
    stats->deltas_skipped += s->pubs[i].skipped;
  }
  region_work_t work = runtime_region_work(&s->rt);
  stats->playout_depth = s->roles.playout_depth;
  tool_roles_playout_totals(&s->roles, &stats->commands_delayed, &stats->commands_superseded,
                            &stats->commands_caught_up);
  stats->region_organs = work.organs;
  stats->region_node_updates = work.node_updates;
  stats->region_block_evals = work.block_evals;
  stats->ntools = s->rt.ntools;
  for (size_t t = 0; t < s->rt.ntools; t++) {
    stats->thr[t] = s->tool[t].thr;
    tool_metrics_fill(&stats->tools[t], &s->rt, t, &s->tool[t].thr, &s->tool[t].tally, sim_ns(s));
  }
  stats->ntasks = s->rt.ntasks;
  stats->sim_time = s->rt.sim_time;
  memcpy(stats->tasks, s->rt.tasks, sizeof stats->tasks);
  for (size_t i = 0; i < s->rt.nstones; i++) stats->stone_removed[i] = s->rt.stones[i].removed;
  for (size_t t = 0; t < s->rt.ntools; t++) stats->peak_force = fmax(stats->peak_force, s->rt.tools[t].peak_force);
  size_t n = s->nstep_us < STEP_RING ? s->nstep_us : STEP_RING;
  summarise_awake(s, n, stats); /* first: the summaries below sort the rings in place */
  vstats_summary_t st = vstats_summarise(s->step_us, n);
  stats->step_us_median = st.median;
  stats->step_us_p99 = st.p99;
  stats->step_us_max = st.max;
  /* The rest of each step (commands, feedback, frames), before the rings are sorted. */
  double *other = malloc((n + 1) * sizeof *other);
  if (other) {
    for (size_t i = 0; i < n; i++) other[i] = s->step_cpu_us[i] - s->step_tissue_us[i];
    vstats_summary_t so = vstats_summarise(other, n);
    stats->step_other_cpu_us_median = so.median;
    stats->step_other_cpu_us_p99 = so.p99;
    free(other);
  }
  vstats_summary_t stt = vstats_summarise(s->step_tissue_us, n);
  stats->step_tissue_cpu_us_median = stt.median;
  stats->step_tissue_cpu_us_p99 = stt.p99;
  vstats_summary_t sc = vstats_summarise(s->step_cpu_us, n);
  stats->step_cpu_us_median = sc.median;
  stats->step_cpu_us_p99 = sc.p99;
  for (size_t i = 0; i < s->rt.norgans; i++) {
    stats->organ_sleeps += s->rt.organs[i].sleep.sleeps;
    stats->organ_wakes += s->rt.organs[i].sleep.wakes;
  }
  /* Up to the end of the last step: a thread stepping several sessions
   * closes them one after the other (seat_group.h). */
  double wall = s->started_ns ? (double)(s->last_end_ns - s->started_ns) * 1e-9 : 0;
  stats->realtime_ratio = wall > 0 ? (s->rt.sim_time - s->sim0) / wall : 0;
  scalpel_print_summary(&s->rt, stdout);
  /* Give reliable late samples (last frame, stop event) a moment to leave. */
  dds_sleepfor(DDS_MSECS(100));
  teardown(s);
  free(s);
}
