/* SPDX-License-Identifier: Apache-2.0 */
#include "view/scene_view.h"

#include <math.h>
#include <stdlib.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "viscera.h"
#include "vtime.h"

/* Samples taken per dds_take call; the loop repeats until a reader is empty. */
#define TAKE_BATCH 16

static void reject(scene_view_t *sv, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void reject(scene_view_t *sv, const char *fmt, ...) {
  sv->rejected++;
  if (!sv->log) return;
  char msg[VERR_MSG_LEN + 128];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  sv->log(sv->log_ctx, msg);
}

static int finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

static void tool_defaults(sv_tool_t *t) {
  t->listed = 0;
  t->name[0] = 0;
  t->radius = SCENE_VIEW_TOOL_RADIUS;
  t->length = SCENE_VIEW_TOOL_LENGTH;
  t->max_force = SCENE_VIEW_TOOL_MAX_FORCE;
  t->st = t->mpf = t->sft = 0;
}

/* A threshold from the wire: kept only when finite and in (0, max_force]. */
static float thr_level(float v, float max_force) { return isfinite(v) && v > 0 && v <= max_force ? v : 0.0f; }

static void organ_defaults(sv_organ_t *o) {
  const float rgb[3] = SCENE_VIEW_ORGAN_RGB;
  o->listed = 0;
  o->name[0] = 0;
  memcpy(o->rgb, rgb, sizeof rgb);
}

/* A SceneInfo replaces the previous one: the scene may have been reloaded. */
static void on_scene_info(scene_view_t *sv, const viscera_SceneInfo *s) {
  /* The sequences are unbounded on the wire (see viscera.idl): enforce the
   * contract's bounds here, before anything is replaced. */
  if (s->organs._length > SCENE_VIEW_MAX_ORGANS || s->tools._length > SCENE_VIEW_MAX_TOOLS) {
    reject(sv, "SceneInfo '%.64s': %u organs, %u tools (at most %d, %d)", s->scene, s->organs._length, s->tools._length,
           SCENE_VIEW_MAX_ORGANS, SCENE_VIEW_MAX_TOOLS);
    return;
  }
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++) organ_defaults(&sv->organs[i]);
  for (int i = 0; i < SCENE_VIEW_MAX_TOOLS; i++) tool_defaults(&sv->tools[i]);
  sv->have_scene = 1;
  snprintf(sv->scene_name, sizeof sv->scene_name, "%s", s->scene);
  for (uint32_t i = 0; i < s->organs._length; i++) {
    const viscera_OrganInfo *oi = &s->organs._buffer[i];
    if (oi->organ_id >= SCENE_VIEW_MAX_ORGANS) {
      reject(sv, "SceneInfo organ entry %u: organ_id %u out of range (0..%d)", i, oi->organ_id,
             SCENE_VIEW_MAX_ORGANS - 1);
      continue;
    }
    if (!finite3(oi->color)) {
      reject(sv, "SceneInfo organ %u: colour is not finite", oi->organ_id);
      continue;
    }
    sv_organ_t *o = &sv->organs[oi->organ_id];
    o->listed = 1;
    snprintf(o->name, sizeof o->name, "%s", oi->name);
    /* Scene colours are display (sRGB) values as people pick them; lighting
     * works in linear RGB. */
    for (int k = 0; k < 3; k++) {
      float c = oi->color[k] < 0 ? 0 : oi->color[k] > 1 ? 1 : oi->color[k];
      o->rgb[k] = c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
    }
  }
  for (uint32_t i = 0; i < s->tools._length; i++) {
    const viscera_ToolInfo *ti = &s->tools._buffer[i];
    if (ti->tool_id >= SCENE_VIEW_MAX_TOOLS) {
      reject(sv, "SceneInfo tool entry %u: tool_id %u out of range (0..%d)", i, ti->tool_id, SCENE_VIEW_MAX_TOOLS - 1);
      continue;
    }
    /* Sizes are drawn: anything not a plausible positive length is refused
     * rather than drawn as a tool covering the scene. */
    if (!(ti->radius > 0 && ti->radius < 1) || !(ti->length >= 0 && ti->length < 10) ||
        !(ti->max_force > 0 && isfinite(ti->max_force))) {
      reject(sv, "SceneInfo tool %u: radius %g, length %g or max_force %g out of range", ti->tool_id,
             (double)ti->radius, (double)ti->length, (double)ti->max_force);
      continue;
    }
    sv_tool_t *t = &sv->tools[ti->tool_id];
    t->listed = 1;
    snprintf(t->name, sizeof t->name, "%s", ti->name);
    t->radius = ti->radius;
    t->length = ti->length;
    t->max_force = ti->max_force;
    t->st = thr_level(ti->st, ti->max_force);
    t->mpf = thr_level(ti->mpf, ti->max_force);
    t->sft = thr_level(ti->sft, ti->max_force);
  }
}

/* Whether a keyframe that arrived by one path (from_chunks) should replace
 * the drawn one: not when it is the drawn keyframe again (the other path's
 * copy), nor when it is older and the drawn one came by the other path (the
 * slower copy of a keyframe already replaced). Otherwise yes, whatever its
 * numbers: a restarted server starts again at 0. */
static int key_wanted(scene_view_t *sv, const sv_organ_t *o, int from_chunks, uint32_t topo, uint32_t seq,
                      const float *pos, size_t npos, const uint32_t *tris, size_t ntri_idx) {
  const organ_state_t *m = &o->mesh;
  if (!m->have_key) return 1;
  if (m->topology_version == topo && m->keyframe_seq == seq && m->nverts * 3 == npos && m->ntris * 3 == ntri_idx &&
      !memcmp(m->key, pos, npos * sizeof *pos) && !memcmp(m->tris, tris, ntri_idx * sizeof *tris)) {
    sv->keys_duplicate++;
    return 0;
  }
  if (o->key_from_chunks != from_chunks &&
      (topo < m->topology_version || (topo == m->topology_version && seq < m->keyframe_seq))) {
    sv->keys_duplicate++;
    return 0;
  }
  return 1;
}

/* A keyframe from either path; returns 1 when drawn. */
static int set_key(scene_view_t *sv, uint32_t organ, int from_chunks, uint32_t topo, uint32_t seq, uint64_t t_ns,
                   const float *pos, size_t npos, const uint32_t *tris, size_t ntri_idx) {
  sv_organ_t *o = &sv->organs[organ];
  const char *what = from_chunks ? "MeshKeyChunk" : "MeshState";
  if (!key_wanted(sv, o, from_chunks, topo, seq, pos, npos, tris, ntri_idx)) return 0;
  verr_t err;
  int rc = organ_state_set_keyframe(&o->mesh, topo, seq, t_ns, pos, npos, tris, ntri_idx, &err);
  if (rc < 0) {
    reject(sv, "%s organ %u (topology %u keyframe %u): %s", what, organ, topo, seq, err.msg);
    return 0;
  }
  if (rc > 0) reject(sv, "MeshDelta organ %u kept for keyframe %u: %s", organ, seq, err.msg);
  o->key_from_chunks = from_chunks;
  if (from_chunks)
    sv->keys_from_chunks++;
  else
    sv->keys_from_state++;
  if (!sv->first_key_mono_ns) sv->first_key_mono_ns = vtime_mono_ns();
  return 1;
}

static void on_mesh_state(scene_view_t *sv, const viscera_MeshState *s) {
  if (s->organ_id >= SCENE_VIEW_MAX_ORGANS) {
    reject(sv, "MeshState: organ_id %u out of range (0..%d)", s->organ_id, SCENE_VIEW_MAX_ORGANS - 1);
    return;
  }
  set_key(sv, s->organ_id, 0, s->topology_version, s->keyframe_seq, s->sim_time_ns, s->positions._buffer,
          s->positions._length, s->triangles._buffer, s->triangles._length);
}

/* A chunk: kept in its organ's assembly; a complete, sound set is decoded
 * and drawn like a MeshState. */
static void on_key_chunk(scene_view_t *sv, const viscera_MeshKeyChunk *s) {
  key_chunk_t c;
  key_chunk_from_wire(s, &c);
  verr_t err;
  if (c.organ_id >= SCENE_VIEW_MAX_ORGANS) {
    reject(sv, "MeshKeyChunk slot %u: organ_id %u out of range (0..%d)", c.slot, c.organ_id, SCENE_VIEW_MAX_ORGANS - 1);
    return;
  }
  key_assembly_t *a = &sv->organs[c.organ_id].chunks;
  int rc = key_assembly_add(a, &c, SCENE_VIEW_MAX_ORGANS, &err);
  if (rc < 0) reject(sv, "MeshKeyChunk organ %u slot %u: %s", c.organ_id, c.slot, err.msg);
  if (rc <= 0) return;
  float *pos;
  uint32_t *tris;
  size_t nv, nt;
  if (key_decode(a->buf, a->total_bytes, &pos, &nv, &tris, &nt, &err)) {
    reject(sv, "MeshKeyChunk organ %u (topology %u keyframe %u): %s", c.organ_id, a->topology_version, a->keyframe_seq,
           err.msg);
    return;
  }
  set_key(sv, c.organ_id, 1, a->topology_version, a->keyframe_seq, a->sim_time_ns, pos, 3 * nv, tris, 3 * nt);
  free(pos);
  free(tris);
}

static void on_mesh_delta(scene_view_t *sv, const viscera_MeshDelta *s) {
  if (s->organ_id >= SCENE_VIEW_MAX_ORGANS) {
    reject(sv, "MeshDelta: organ_id %u out of range (0..%d)", s->organ_id, SCENE_VIEW_MAX_ORGANS - 1);
    return;
  }
  const organ_delta_t d = {.topology_version = s->topology_version,
                           .keyframe_seq = s->keyframe_seq,
                           .frame_seq = s->frame_seq,
                           .sim_time_ns = s->sim_time_ns,
                           .quant_step = s->quant_step,
                           .indices = s->indices._buffer,
                           .count = s->indices._length,
                           .dq = s->dq._buffer,
                           .dq_len = s->dq._length};
  verr_t err;
  if (organ_state_delta(&sv->organs[s->organ_id].mesh, &d, &err) < 0)
    reject(sv, "MeshDelta organ %u (topology %u keyframe %u frame %u): %s", s->organ_id, s->topology_version,
           s->keyframe_seq, s->frame_seq, err.msg);
}

static void on_tool_command(scene_view_t *sv, const viscera_ToolCommand *s) {
  if (s->tool_id >= SCENE_VIEW_MAX_TOOLS) {
    reject(sv, "ToolCommand: tool_id %u out of range (0..%d)", s->tool_id, SCENE_VIEW_MAX_TOOLS - 1);
    return;
  }
  if (!finite3(s->position)) {
    reject(sv, "ToolCommand tool %u: position is not finite", s->tool_id);
    return;
  }
  sv_tool_t *t = &sv->tools[s->tool_id];
  memcpy(t->tip, s->position, sizeof t->tip);
  t->have_pose = 1;
}

static void on_contact(scene_view_t *sv, const viscera_ContactFeedback *s) {
  if (s->tool_id >= SCENE_VIEW_MAX_TOOLS) {
    reject(sv, "ContactFeedback: tool_id %u out of range (0..%d)", s->tool_id, SCENE_VIEW_MAX_TOOLS - 1);
    return;
  }
  /* Read the boolean's byte: a value other than 0/1 must be refused, and
   * loading it as a C bool would already be undefined behaviour. */
  unsigned char contact;
  memcpy(&contact, &s->in_contact, 1);
  if (contact > 1 || !finite3(s->proxy_position) || !finite3(s->force)) {
    reject(sv, "ContactFeedback tool %u: in_contact byte %u, or proxy or force not finite", s->tool_id, contact);
    return;
  }
  sv_tool_t *t = &sv->tools[s->tool_id];
  t->have_contact = 1;
  t->in_contact = contact;
  memcpy(t->proxy, s->proxy_position, sizeof t->proxy);
  memcpy(t->force, s->force, sizeof t->force);
}

static void on_object(scene_view_t *sv, const viscera_ObjectState *s) {
  if (s->object_id >= SCENE_VIEW_MAX_OBJECTS) {
    reject(sv, "ObjectState: object_id %u out of range (0..%d)", s->object_id, SCENE_VIEW_MAX_OBJECTS - 1);
    return;
  }
  unsigned char removed;
  memcpy(&removed, &s->removed, 1);
  int colour_ok = 1;
  for (int k = 0; k < 3; k++) colour_ok &= s->color[k] >= 0 && s->color[k] <= 1;
  /* A stone is millimetres; anything beyond 10 cm is a corrupt sample. */
  if (removed > 1 || !finite3(s->position) || !(s->radius > 0 && s->radius <= 0.1f) || !colour_ok) {
    reject(sv,
           "ObjectState object %u: position not finite, radius not in (0, 0.1] m, colour outside 0..1 or "
           "removed byte %u",
           s->object_id, removed);
    return;
  }
  sv_object_t *o = &sv->objects[s->object_id];
  o->have = 1;
  memcpy(o->pos, s->position, sizeof o->pos);
  o->radius = s->radius;
  memcpy(o->rgb, s->color, sizeof o->rgb);
  o->held = s->held_by >= 0;
  o->removed = removed;
}

/* Samples kept per instance until the next poll: a writer that is not the
 * server gets its first samples in before it is judged and blocked, and
 * must not push the server's keyframe out meanwhile. */
#define SERVER_DEPTH 8

int scene_view_open(scene_view_t *sv, int domain, const char *partition, scene_view_log_fn log, void *log_ctx,
                    verr_t *err) {
  memset(sv, 0, sizeof *sv);
  sv->log = log;
  sv->log_ctx = log_ctx;
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++) organ_defaults(&sv->organs[i]);
  for (int i = 0; i < SCENE_VIEW_MAX_TOOLS; i++) tool_defaults(&sv->tools[i]);
  vdds_gate_init(&sv->gate_state, SCENE_VIEW_MAX_ORGANS, NULL, NULL);
  vdds_gate_init(&sv->gate_delta, SCENE_VIEW_MAX_ORGANS, NULL, NULL);
  vdds_gate_init(&sv->gate_cmd, SCENE_VIEW_MAX_TOOLS, NULL, NULL);
  vdds_gate_init(&sv->gate_contact, SCENE_VIEW_MAX_TOOLS, NULL, NULL);
  vdds_gate_init(&sv->gate_object, SCENE_VIEW_MAX_OBJECTS, NULL, NULL);
  vdds_gate_init(&sv->gate_chunk, SCENE_VIEW_MAX_ORGANS * KEY_CHUNKS_MAX, NULL, NULL);
  if (vdds_open(&sv->dds, (dds_domainid_t)domain, partition, err)) return -1;
  if (seat_server_open(&sv->server, sv->dds.participant, err)) {
    vdds_close(&sv->dds);
    return -1;
  }
  struct {
    dds_entity_t *rd;
    vdds_topic_id_t topic;
    vdds_gate_t *gate;
    int max_instances;
    int depth; /* samples per instance; 0: SERVER_DEPTH */
    int live;  /* volatile (dds/vdds_gate.h vdds_reader_gated_live) */
  } rds[] = {{&sv->rd_scene, VT_SCENE_INFO, NULL, 0, 0, 0},
             {&sv->rd_state, VT_MESH_STATE, &sv->gate_state, SCENE_VIEW_MAX_ORGANS, 0, 0},
             {&sv->rd_delta, VT_MESH_DELTA, &sv->gate_delta, SCENE_VIEW_MAX_ORGANS, 0, 0},
             {&sv->rd_cmd, VT_TOOL_COMMAND, &sv->gate_cmd, SCENE_VIEW_MAX_TOOLS, 0, 0},
             {&sv->rd_contact, VT_CONTACT_FEEDBACK, &sv->gate_contact, SCENE_VIEW_MAX_TOOLS, 0, 0},
             {&sv->rd_object, VT_OBJECT_STATE, &sv->gate_object, SCENE_VIEW_MAX_OBJECTS, 0, 0},
             /* Chunks: 16,384 slots of at most 1.1 kB; 2 per slot bounds what a
              * flood can hold before its writer is judged to about 36 MB per
              * reader, and still lets one impostor's sample sit beside the
              * server's. */
             {&sv->rd_chunk, VT_MESH_KEY_CHUNK, &sv->gate_chunk, SCENE_VIEW_MAX_ORGANS * KEY_CHUNKS_MAX, 2, 0},
             {&sv->rd_chunk_live, VT_MESH_KEY_CHUNK, &sv->gate_chunk, SCENE_VIEW_MAX_ORGANS * KEY_CHUNKS_MAX, 2, 1}};
  for (size_t i = 0; i < sizeof rds / sizeof rds[0]; i++) {
    *rds[i].rd = rds[i].gate ? vdds_reader_gated_live(&sv->dds, rds[i].topic, rds[i].gate,
                                                      rds[i].depth ? rds[i].depth : SERVER_DEPTH, rds[i].max_instances,
                                                      rds[i].live, NULL, err)
                             : vdds_reader(&sv->dds, rds[i].topic, err);
    /* Keyframe chunks are optional (vdds.c: not permitted by an older PKI):
     * keyframes then come as MeshState only. */
    if (*rds[i].rd < 0 && rds[i].topic == VT_MESH_KEY_CHUNK) *rds[i].rd = 0;
    if (*rds[i].rd < 0) {
      vdds_close(&sv->dds);
      return -1;
    }
  }
  return 0;
}

void scene_view_close(scene_view_t *sv) {
  vdds_close(&sv->dds);
  seat_server_close(&sv->server);
  vdds_gate_t *gates[] = {&sv->gate_state,   &sv->gate_delta,  &sv->gate_cmd,
                          &sv->gate_contact, &sv->gate_object, &sv->gate_chunk};
  for (size_t i = 0; i < sizeof gates / sizeof gates[0]; i++) vdds_gate_destroy(gates[i]);
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++) {
    organ_state_free(&sv->organs[i].mesh);
    key_assembly_free(&sv->organs[i].chunks);
  }
}

/* A tool whose writer is gone (haptic client quit, server stopped) would
 * otherwise stay frozen on screen at its last pose. Meshes are kept: the
 * last state of a stopped session is still worth looking at. */
static void on_tool_gone(scene_view_t *sv, const viscera_ToolCommand *s) {
  if (s->tool_id < SCENE_VIEW_MAX_TOOLS) sv->tools[s->tool_id].have_pose = 0;
}

static void on_contact_gone(scene_view_t *sv, const viscera_ContactFeedback *s) {
  if (s->tool_id < SCENE_VIEW_MAX_TOOLS) sv->tools[s->tool_id].have_contact = 0;
}

typedef void (*handler_fn)(scene_view_t *sv, const void *sample);

/* Who may write a topic: anyone, the seat's server (SceneInfo decides
 * who that is), or the SceneInfo itself. */
typedef enum source { FROM_ANYONE, FROM_SERVER, SCENE_INFO } source_t;

/* 1 when sample i may be used (counts and blocks the rest). */
static int believed(scene_view_t *sv, dds_entity_t rd, source_t src, vdds_gate_t *gate, const dds_sample_info_t *info,
                    const void *sample) {
  if (src == FROM_ANYONE) return 1;
  if (src == SCENE_INFO) {
    if (!info->valid_data) return 0;
    if (seat_server_scene(&sv->server, rd, info, sample)) return 1;
    sv->ignored++;
    return 0;
  }
  seat_verdict_t v = seat_server_from(&sv->server, rd, info->publication_handle);
  if (v == SEAT_FROM_SERVER) return 1;
  if (v == SEAT_NOT_SERVER && gate) vdds_gate_block(gate, info->publication_handle, VDDS_GATE_ANY_KEY);
  if (info->valid_data) sv->ignored++;
  return 0;
}

/* Takes with loans (no copies of large meshes) until the reader is empty.
 * `gone` (may be NULL) runs for an instance that is no longer alive; its
 * sample's key fields are valid even when the data is not. A server
 * topic waits in its reader until the seat's server is known. */
static int take_all(scene_view_t *sv, dds_entity_t rd, handler_fn handle, handler_fn gone, const char *topic,
                    source_t src, vdds_gate_t *gate, verr_t *err) {
  int taken = 0;
  if (src == FROM_SERVER && !sv->server.known) return 0;
  for (;;) {
    void *samples[TAKE_BATCH] = {NULL};
    dds_sample_info_t infos[TAKE_BATCH];
    dds_return_t n = dds_take(rd, samples, infos, TAKE_BATCH, TAKE_BATCH);
    if (n < 0) return verr_set(err, "DDS: take on %s failed: %s", topic, dds_strretcode(n));
    for (int i = 0; i < n; i++) {
      if (!believed(sv, rd, src, gate, &infos[i], samples[i])) continue;
      if (infos[i].valid_data) {
        handle(sv, samples[i]);
        taken++;
      }
      if (gone && infos[i].instance_state != DDS_IST_ALIVE) gone(sv, samples[i]);
    }
    if (n > 0) dds_return_loan(rd, samples, n);
    if (n < TAKE_BATCH) return taken;
  }
}

static void h_scene(scene_view_t *sv, const void *s) { on_scene_info(sv, s); }
static void h_state(scene_view_t *sv, const void *s) { on_mesh_state(sv, s); }
static void h_chunk(scene_view_t *sv, const void *s) { on_key_chunk(sv, s); }
static void h_delta(scene_view_t *sv, const void *s) { on_mesh_delta(sv, s); }
static void h_cmd(scene_view_t *sv, const void *s) { on_tool_command(sv, s); }
static void h_contact(scene_view_t *sv, const void *s) { on_contact(sv, s); }
static void h_tool_gone(scene_view_t *sv, const void *s) { on_tool_gone(sv, s); }
static void h_contact_gone(scene_view_t *sv, const void *s) { on_contact_gone(sv, s); }
static void h_object(scene_view_t *sv, const void *s) { on_object(sv, s); }

int scene_view_poll(scene_view_t *sv, verr_t *err) {
  /* SceneInfo first (colours), keyframes before deltas so that a keyframe
   * and its first delta arriving together apply in one poll. */
  const struct {
    dds_entity_t rd;
    handler_fn h, gone;
    const char *name;
    source_t src;
    vdds_gate_t *gate;
  } order[] = {{sv->rd_scene, h_scene, NULL, "SceneInfo", SCENE_INFO, NULL},
               {sv->rd_chunk_live, h_chunk, NULL, "MeshKeyChunk", FROM_SERVER, &sv->gate_chunk},
               {sv->rd_chunk, h_chunk, NULL, "MeshKeyChunk", FROM_SERVER, &sv->gate_chunk},
               {sv->rd_state, h_state, NULL, "MeshState", FROM_SERVER, &sv->gate_state},
               {sv->rd_delta, h_delta, NULL, "MeshDelta", FROM_SERVER, &sv->gate_delta},
               {sv->rd_cmd, h_cmd, h_tool_gone, "ToolCommand", FROM_ANYONE, &sv->gate_cmd},
               {sv->rd_contact, h_contact, h_contact_gone, "ContactFeedback", FROM_SERVER, &sv->gate_contact},
               {sv->rd_object, h_object, NULL, "ObjectState", FROM_SERVER, &sv->gate_object}};
  int total = 0;
  for (size_t i = 0; i < sizeof order / sizeof order[0]; i++) {
    if (order[i].rd == 0) continue; /* an optional reader not created */
    int n = take_all(sv, order[i].rd, order[i].h, order[i].gone, order[i].name, order[i].src, order[i].gate, err);
    if (n < 0) return -1;
    total += n;
  }
  return total;
}

int scene_view_any_keyframe(const scene_view_t *sv) {
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++)
    if (sv->organs[i].mesh.have_key) return 1;
  return 0;
}

int scene_view_complete(const scene_view_t *sv) {
  if (!scene_view_any_keyframe(sv)) return 0;
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++)
    if (sv->organs[i].listed && !sv->organs[i].mesh.have_key) return 0;
  return 1;
}

int scene_view_key_bounds(const scene_view_t *sv, double bmin[3], double bmax[3]) {
  int any = 0;
  for (int k = 0; k < 3; k++) bmin[k] = INFINITY, bmax[k] = -INFINITY;
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++) {
    const organ_state_t *o = &sv->organs[i].mesh;
    if (!o->have_key) continue;
    any = 1;
    for (size_t v = 0; v < o->nverts; v++)
      for (int k = 0; k < 3; k++) {
        double x = o->key[3 * v + k];
        if (x < bmin[k]) bmin[k] = x;
        if (x > bmax[k]) bmax[k] = x;
      }
  }
  return any ? 0 : -1;
}

uint64_t scene_view_sim_time_ns(const scene_view_t *sv) {
  uint64_t t = 0;
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++)
    if (sv->organs[i].mesh.have_key && sv->organs[i].mesh.sim_time_ns > t) t = sv->organs[i].mesh.sim_time_ns;
  return t;
}

long long scene_view_frame_seq(const scene_view_t *sv) {
  long long f = -1;
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++) {
    long long s = organ_state_frame_seq(&sv->organs[i].mesh);
    if (s > f) f = s;
  }
  return f;
}

int scene_view_primary_tool(const scene_view_t *sv) {
  for (int i = 0; i < SCENE_VIEW_MAX_TOOLS; i++)
    if (sv->tools[i].have_pose || sv->tools[i].have_contact) return i;
  return -1;
}
