/* SPDX-License-Identifier: Apache-2.0 */
#include "guide_slot.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "station.h"
#include "vtime.h"

_Static_assert(GUIDE_STATION_MAX == VDDS_STATION_MAX, "guide_force.h and vdds.h disagree on station length");

/* vdds_gate_check_fn: our tool's commands with a finite position only
 * (reason 1: another tool, 2: not finite). */
static int peer_command_check(const void *sample, void *arg) {
  const viscera_ToolCommand *c = sample;
  const guide_slot_t *s = arg;
  if (c->tool_id != s->tool_id) return 1;
  return isfinite(c->position[0]) && isfinite(c->position[1]) && isfinite(c->position[2]) ? 0 : 2;
}

/* vdds_gate_check_fn: our tool's ToolRole only (reason 1). */
static int own_role_check(const void *sample, void *arg) {
  return ((const viscera_ToolRole *)sample)->tool_id == ((const guide_slot_t *)arg)->tool_id ? 0 : 1;
}

int guide_slot_init(guide_slot_t *s, uint32_t tool_id) {
  memset(s, 0, sizeof *s);
  s->tool_id = tool_id;
  vdds_gate_init(&s->gate, tool_id + 1, peer_command_check, s);
  vdds_gate_init(&s->role_gate, tool_id + 1, own_role_check, s);
  return pthread_mutex_init(&s->lock, NULL) == 0 ? 0 : -1;
}

void guide_slot_destroy(guide_slot_t *s) {
  pthread_mutex_destroy(&s->lock);
  vdds_gate_destroy(&s->gate);
  vdds_gate_destroy(&s->role_gate);
}

/* A station name from the wire: "" (anonymous / any) or a valid station.
 * The owner may also arrive as "*" (the control verb's spelling of "any"). */
static int copy_station(char out[GUIDE_STATION_MAX], const char *in, size_t cap, int star_is_any) {
  size_t n = strnlen(in, cap);
  if (n == cap || n >= GUIDE_STATION_MAX) return -1; /* unterminated or too long */
  if (star_is_any && n == 1 && in[0] == '*') n = 0;
  if (n > 0 && !station_name_valid(in)) return -1;
  memcpy(out, in, n);
  out[n] = 0;
  return 0;
}

int guide_slot_role(guide_slot_t *s, const viscera_ToolRole *r) {
  if (r->tool_id != s->tool_id) return 0;
  guide_role_t g;
  memset(&g, 0, sizeof g);
  g.known = 1;
  g.version = r->version;
  g.authority = r->authority;
  g.coupling_stiffness = r->coupling_stiffness;
  int ok = copy_station(g.owner, r->owner, sizeof r->owner, 1) == 0 &&
           copy_station(g.guide, r->guide, sizeof r->guide, 0) == 0;
  /* With a guide the numbers must be usable; without one they are unused
   * (the contract says 0) but still must not be garbage. */
  if (ok && g.guide[0]) ok = guide_role_valid(&g);
  if (ok && !g.guide[0]) ok = isfinite(g.authority) && isfinite(g.coupling_stiffness);
  pthread_mutex_lock(&s->lock);
  if (ok) {
    s->role = g;
    s->roles_received++;
  } else {
    s->roles_rejected++;
  }
  pthread_mutex_unlock(&s->lock);
  return ok ? 1 : -1;
}

void guide_slot_role_lost(guide_slot_t *s) {
  pthread_mutex_lock(&s->lock);
  memset(&s->role, 0, sizeof s->role);
  pthread_mutex_unlock(&s->lock);
}

int guide_slot_command(guide_slot_t *s, const char *station, const float pos[3], uint64_t now) {
  int finite = isfinite(pos[0]) && isfinite(pos[1]) && isfinite(pos[2]);
  pthread_mutex_lock(&s->lock);
  if (!finite) {
    s->bad_samples++;
    pthread_mutex_unlock(&s->lock);
    return -1;
  }
  /* The station's entry, else an empty one, else the stalest. */
  int slot = -1, empty = -1, oldest = 0;
  for (int i = 0; i < GUIDE_SLOT_STATIONS; i++) {
    const guide_station_pos_t *e = &s->pos[i];
    if (e->arrival_mono_ns && strcmp(e->station, station) == 0) {
      slot = i;
      break;
    }
    if (!e->arrival_mono_ns && empty < 0) empty = i;
    if (e->arrival_mono_ns < s->pos[oldest].arrival_mono_ns) oldest = i;
  }
  if (slot < 0) slot = empty >= 0 ? empty : oldest;
  guide_station_pos_t *e = &s->pos[slot];
  if (!e->arrival_mono_ns || strcmp(e->station, station)) e->transit_s = -1; /* a new station */
  snprintf(e->station, sizeof e->station, "%s", station);
  for (int k = 0; k < 3; k++) e->pos[k] = pos[k];
  e->arrival_mono_ns = now ? now : 1;
  s->peer_samples++;
  pthread_mutex_unlock(&s->lock);
  return 0;
}

void guide_slot_transit(guide_slot_t *s, const char *station, double transit_s) {
  if (!(transit_s > 0) || !(transit_s < GUIDE_TRANSIT_MAX_S)) return;
  pthread_mutex_lock(&s->lock);
  for (int i = 0; i < GUIDE_SLOT_STATIONS; i++) {
    guide_station_pos_t *e = &s->pos[i];
    if (!e->arrival_mono_ns || strcmp(e->station, station)) continue;
    e->transit_s = e->transit_s < 0 ? transit_s : e->transit_s + GUIDE_TRANSIT_GAIN * (transit_s - e->transit_s);
    break;
  }
  pthread_mutex_unlock(&s->lock);
}

void guide_slot_read(guide_slot_t *s, const char *own, uint64_t now, guide_view_t *out) {
  memset(out, 0, sizeof *out);
  out->peer_transit_s = -1;
  pthread_mutex_lock(&s->lock);
  out->role = s->role;
  guide_side_t side = guide_side_of(&s->role, own);
  const guide_station_pos_t *best = NULL;
  for (int i = 0; i < GUIDE_SLOT_STATIONS && side != GUIDE_SIDE_NONE; i++) {
    const guide_station_pos_t *e = &s->pos[i];
    if (!e->arrival_mono_ns || !guide_is_peer(&s->role, side, e->station)) continue;
    if (!best || e->arrival_mono_ns > best->arrival_mono_ns) best = e;
  }
  if (best) {
    out->have_peer = 1;
    memcpy(out->peer, best->pos, sizeof out->peer);
    out->peer_age_s = now > best->arrival_mono_ns ? (double)(now - best->arrival_mono_ns) * 1e-9 : 0.0;
    out->peer_transit_s = best->transit_s;
    memcpy(out->peer_station, best->station, sizeof out->peer_station);
  }
  pthread_mutex_unlock(&s->lock);
}

/* Listener thread: the station behind a publication handle, cached. */
static void station_of(guide_slot_t *s, dds_entity_t reader, dds_instance_handle_t h, char out[GUIDE_STATION_MAX]) {
  int oldest = 0;
  for (int i = 0; i < GUIDE_SLOT_HANDLES; i++) {
    guide_handle_station_t *e = &s->handles[i];
    if (e->handle == h) {
      e->used = ++s->handle_clock;
      memcpy(out, e->station, GUIDE_STATION_MAX);
      return;
    }
    if (e->used < s->handles[oldest].used) oldest = i;
  }
  /* A writer no longer matched (it just left) stays anonymous and uncached. */
  if (vdds_station_of_writer(reader, h, out) != 0) return;
  guide_handle_station_t *e = &s->handles[oldest];
  e->handle = h;
  e->used = ++s->handle_clock;
  memcpy(e->station, out, GUIDE_STATION_MAX);
}

#define GUIDE_TAKE 16

static void on_command(dds_entity_t reader, void *arg) {
  guide_slot_t *s = arg;
  void *samples[GUIDE_TAKE] = {0};
  dds_sample_info_t infos[GUIDE_TAKE];
  int n = dds_take(reader, samples, infos, GUIDE_TAKE, GUIDE_TAKE);
  uint64_t now = vtime_mono_ns();
  int64_t wall = vtime_wall_ns();
  for (int i = 0; i < n; i++) {
    const viscera_ToolCommand *c = samples[i];
    if (!infos[i].valid_data || c->tool_id != s->tool_id) continue;
    if (infos[i].publication_handle == s->own_writer) {
      pthread_mutex_lock(&s->lock);
      s->own_samples_skipped++;
      pthread_mutex_unlock(&s->lock);
      continue;
    }
    char station[GUIDE_STATION_MAX];
    station_of(s, reader, infos[i].publication_handle, station);
    if (guide_slot_command(s, station, c->position, now) == 0)
      guide_slot_transit(s, station, (double)(wall - infos[i].source_timestamp) * 1e-9);
  }
  if (n > 0) dds_return_loan(reader, samples, n);
}

static void on_role(dds_entity_t reader, void *arg) {
  guide_slot_t *s = arg;
  void *samples[GUIDE_TAKE] = {0};
  dds_sample_info_t infos[GUIDE_TAKE];
  int n = dds_take(reader, samples, infos, GUIDE_TAKE, GUIDE_TAKE);
  for (int i = 0; i < n; i++) {
    const viscera_ToolRole *r = samples[i];
    seat_verdict_t v = s->server ? seat_server_from(s->server, reader, infos[i].publication_handle) : SEAT_FROM_SERVER;
    if (v != SEAT_FROM_SERVER) { /* not the seat's server: counted, never coupled to */
      if (v == SEAT_NOT_SERVER) vdds_gate_block(&s->role_gate, infos[i].publication_handle, VDDS_GATE_ANY_KEY);
      if (infos[i].valid_data) {
        pthread_mutex_lock(&s->lock);
        s->roles_ignored++;
        pthread_mutex_unlock(&s->lock);
      }
      continue;
    }
    if (infos[i].valid_data) {
      guide_slot_role(s, r);
    } else if (r->tool_id == s->tool_id && infos[i].instance_state != DDS_IST_ALIVE) {
      /* Disposed, or its writer (the server) is gone: no role any more, so
       * no coupling to a peer the server no longer mixes in. */
      guide_slot_role_lost(s);
    }
  }
  if (n > 0) dds_return_loan(reader, samples, n);
}

int guide_slot_attach(guide_slot_t *s, vdds_t *v, dds_entity_t own_writer, verr_t *err) {
  if (dds_get_instance_handle(own_writer, &s->own_writer) != DDS_RETCODE_OK) {
    verr_set(err, "DDS: cannot get the instance handle of the ToolCommand writer");
    return -1;
  }
  dds_listener_t *l = dds_create_listener(s);
  dds_lset_data_available(l, on_role);
  dds_entity_t r_role = vdds_reader_gated(v, VT_TOOL_ROLE, &s->role_gate, 0, 1, l, err);
  dds_lset_data_available(l, on_command);
  /* Every writer of the tool shares one keyed instance: keep a few samples
   * so our own 1 kHz commands cannot push the peer's out of the history
   * before the listener takes them. */
  dds_qos_t *q = vdds_topic_qos(VT_TOOL_COMMAND);
  dds_entity_t tp = r_role < 0 ? r_role : vdds_gated_topic(v, VT_TOOL_COMMAND, &s->gate, err), r_cmd = tp;
  if (tp >= 0) {
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, GUIDE_TAKE);
    /* Our own 1 kHz commands are not delivered at all (no listener call
     * per tick for nothing); the handle check in on_command stays for a
     * DDS that delivers them anyway. */
    dds_qset_ignorelocal(q, DDS_IGNORELOCAL_PARTICIPANT);
    dds_qset_resource_limits(q, DDS_LENGTH_UNLIMITED, 1, DDS_LENGTH_UNLIMITED); /* our tool's instance only */
    r_cmd = dds_create_reader(v->subscriber, tp, q, l);
    if (r_cmd < 0) verr_set(err, "DDS: cannot create the ToolCommand reader: %s", dds_strretcode(r_cmd));
  }
  dds_delete_qos(q);
  dds_delete_listener(l);
  return r_role < 0 || r_cmd < 0 ? -1 : 0;
}
