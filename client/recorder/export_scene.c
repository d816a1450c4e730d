/* SPDX-License-Identifier: Apache-2.0 */
#include "export_scene.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "recording/rec_decode.h"
#include "recording/rec_types.h"
#include "viscera.h"

#define MAX_ORGANS 16

typedef struct organ {
  bool have_key;
  uint32_t topology_version, keyframe_seq;
  float *key, *cur; /* 3 per vertex */
  uint32_t nverts;
  uint32_t *tris;
  uint32_t ntris; /* indices, 3 per triangle */
  float color[3];
  char name[64];
  uint64_t last_emit_ns;
  bool emitted;
} organ_t;

struct export_scene {
  mcap_writer_t *w;
  uint16_t channel;
  uint32_t seq;
  organ_t organs[MAX_ORGANS];
  uint64_t messages, skipped;
  rt_str_t json;
};

/* A JSON Schema naming the fields Foxglove reads; the schema name makes
 * Foxglove treat the channel as scene updates. */
static const char SCHEMA[] =
    "{\"title\":\"foxglove.SceneUpdate\",\"type\":\"object\",\"properties\":{"
    "\"deletions\":{\"type\":\"array\"},\"entities\":{\"type\":\"array\",\"items\":{\"type\":\"object\",\"properties\":"
    "{"
    "\"timestamp\":{\"type\":\"object\"},\"frame_id\":{\"type\":\"string\"},\"id\":{\"type\":\"string\"},"
    "\"lifetime\":{\"type\":\"object\"},\"frame_locked\":{\"type\":\"boolean\"},\"metadata\":{\"type\":\"array\"},"
    "\"triangles\":{\"type\":\"array\"}}}}}}";

export_scene_t *export_scene_open(mcap_writer_t *w, uint16_t schema_id, uint16_t channel_id, verr_t *err) {
  export_scene_t *s = calloc(1, sizeof *s);
  if (!s) {
    verr_set(err, "out of memory");
    return NULL;
  }
  s->w = w;
  s->channel = channel_id;
  const char *meta[] = {"source", "viscera MeshState + MeshDelta"};
  if (mcap_schema(w, schema_id, "foxglove.SceneUpdate", "jsonschema", SCHEMA, sizeof SCHEMA - 1, err) < 0 ||
      mcap_channel(w, channel_id, schema_id, "/viscera/scene", "json", meta, 1, err) < 0) {
    free(s);
    return NULL;
  }
  return s;
}

static int emit(export_scene_t *s, uint32_t id, uint64_t t_ns, verr_t *err) {
  organ_t *o = &s->organs[id];
  rt_str_t *j = &s->json;
  j->len = 0;
  rt_str_printf(
      j,
      "{\"deletions\":[],\"entities\":[{\"timestamp\":{\"sec\":%llu,\"nsec\":%u},\"frame_id\":\"world\","
      "\"id\":\"organ%u\",\"lifetime\":{\"sec\":0,\"nsec\":0},\"frame_locked\":false,\"metadata\":[{\"key\":"
      "\"name\",\"value\":\"%s\"}],\"triangles\":[{\"pose\":{\"position\":{\"x\":0,\"y\":0,\"z\":0},"
      "\"orientation\":{\"x\":0,\"y\":0,\"z\":0,\"w\":1}},\"color\":{\"r\":%.3f,\"g\":%.3f,\"b\":%.3f,\"a\":1},"
      "\"points\":[",
      (unsigned long long)(t_ns / 1000000000u), (unsigned)(t_ns % 1000000000u), id, o->name, (double)o->color[0],
      (double)o->color[1], (double)o->color[2]);
  for (uint32_t v = 0; v < o->nverts; v++)
    rt_str_printf(j, "%s{\"x\":%.6g,\"y\":%.6g,\"z\":%.6g}", v ? "," : "", (double)o->cur[3 * v],
                  (double)o->cur[3 * v + 1], (double)o->cur[3 * v + 2]);
  rt_str_printf(j, "],\"indices\":[");
  for (uint32_t k = 0; k < o->ntris; k++) rt_str_printf(j, "%s%u", k ? "," : "", o->tris[k]);
  rt_str_printf(j, "]}]}]}");
  if (j->oom) return verr_set(err, "out of memory");
  o->last_emit_ns = t_ns;
  o->emitted = true;
  s->messages++;
  return mcap_message(s->w, s->channel, s->seq++, t_ns, t_ns, j->s, j->len, err);
}

static void on_scene_info(export_scene_t *s, const viscera_SceneInfo *si) {
  for (uint32_t i = 0; i < si->organs._length; i++) {
    const viscera_OrganInfo *oi = &si->organs._buffer[i];
    if (oi->organ_id >= MAX_ORGANS) continue;
    organ_t *o = &s->organs[oi->organ_id];
    memcpy(o->color, oi->color, sizeof o->color);
    snprintf(o->name, sizeof o->name, "%.63s", oi->name);
    /* names go into JSON text: keep them plain */
    for (char *c = o->name; *c; c++)
      if (*c == '"' || *c == '\\' || (unsigned char)*c < 0x20) *c = '_';
  }
}

static int on_keyframe(export_scene_t *s, const viscera_MeshState *m, uint64_t t, verr_t *err) {
  if (m->organ_id >= MAX_ORGANS || m->positions._length % 3 || m->triangles._length % 3) return 1;
  uint32_t nv = m->positions._length / 3;
  for (uint32_t k = 0; k < m->triangles._length; k++)
    if (m->triangles._buffer[k] >= nv) return 1;
  organ_t *o = &s->organs[m->organ_id];
  float *key = malloc((nv ? nv : 1) * 3 * sizeof *key), *cur = malloc((nv ? nv : 1) * 3 * sizeof *cur);
  uint32_t *tris = malloc((m->triangles._length ? m->triangles._length : 1) * sizeof *tris);
  if (!key || !cur || !tris) {
    free(key), free(cur), free(tris);
    return verr_set(err, "out of memory");
  }
  memcpy(key, m->positions._buffer, (size_t)nv * 3 * sizeof *key);
  memcpy(cur, key, (size_t)nv * 3 * sizeof *cur);
  memcpy(tris, m->triangles._buffer, m->triangles._length * sizeof *tris);
  free(o->key), free(o->cur), free(o->tris);
  o->key = key, o->cur = cur, o->tris = tris;
  o->nverts = nv, o->ntris = m->triangles._length;
  o->topology_version = m->topology_version;
  o->keyframe_seq = m->keyframe_seq;
  o->have_key = true;
  if (!o->name[0]) snprintf(o->name, sizeof o->name, "organ %u", m->organ_id);
  if (!o->color[0] && !o->color[1] && !o->color[2]) o->color[0] = 0.8f, o->color[1] = 0.4f, o->color[2] = 0.4f;
  return emit(s, m->organ_id, t, err) < 0 ? -1 : 0;
}

static int on_delta(export_scene_t *s, const viscera_MeshDelta *d, uint64_t t, verr_t *err) {
  if (d->organ_id >= MAX_ORGANS) return 1;
  organ_t *o = &s->organs[d->organ_id];
  if (!o->have_key || d->topology_version != o->topology_version || d->keyframe_seq != o->keyframe_seq) return 1;
  if (d->dq._length != 3 * d->indices._length) return 1;
  /* cumulative since the keyframe: start from it */
  memcpy(o->cur, o->key, (size_t)o->nverts * 3 * sizeof *o->cur);
  for (uint32_t i = 0; i < d->indices._length; i++) {
    uint32_t v = d->indices._buffer[i];
    if (v >= o->nverts) return 1;
    for (int k = 0; k < 3; k++) o->cur[3 * v + k] = o->key[3 * v + k] + d->quant_step * d->dq._buffer[3 * i + k];
  }
  if (o->emitted && t < o->last_emit_ns + EXPORT_SCENE_PERIOD_NS) return 0;
  return emit(s, d->organ_id, t, err) < 0 ? -1 : 0;
}

int export_scene_row(export_scene_t *s, const char *topic, const recfile_row_t *row, verr_t *err) {
  const dds_topic_descriptor_t *desc = !strcmp(topic, "viscera_MeshState")   ? &viscera_MeshState_desc
                                       : !strcmp(topic, "viscera_MeshDelta") ? &viscera_MeshDelta_desc
                                       : !strcmp(topic, "viscera_SceneInfo") ? &viscera_SceneInfo_desc
                                                                             : NULL;
  if (!desc || row->kind != 0) return 0;
  union {
    viscera_MeshState ms;
    viscera_MeshDelta md;
    viscera_SceneInfo si;
  } u;
  if (!rec_decode_cdr(row->cdr, row->cdr_len, desc, &u)) {
    s->skipped++;
    return 0;
  }
  uint64_t t = row->source_ts_ns > 0 ? (uint64_t)row->source_ts_ns : 0;
  int r = 0;
  if (desc == &viscera_SceneInfo_desc)
    on_scene_info(s, &u.si);
  else if (desc == &viscera_MeshState_desc)
    r = on_keyframe(s, &u.ms, t, err);
  else
    r = on_delta(s, &u.md, t, err);
  if (r > 0) s->skipped++;
  rec_decode_free(&u, desc);
  return r < 0 ? -1 : 0;
}

void export_scene_close(export_scene_t *s, uint64_t *messages, uint64_t *skipped) {
  if (!s) return;
  *messages = s->messages;
  *skipped = s->skipped;
  for (int i = 0; i < MAX_ORGANS; i++) free(s->organs[i].key), free(s->organs[i].cur), free(s->organs[i].tris);
  rt_str_free(&s->json);
  free(s);
}
