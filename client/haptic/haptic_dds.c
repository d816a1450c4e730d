/* SPDX-License-Identifier: Apache-2.0 */
#include "haptic_dds.h"

#include <stdio.h>

#include "viscera.h"
#include "vtime.h"

/* SceneInfo as it arrives: adopts the seat's server (a restarted one too)
 * and gives the slot the scene's limits for the tool. */
static void on_scene(dds_entity_t reader, void *arg) {
  haptic_dds_t *h = arg;
  void *samples[4] = {0};
  dds_sample_info_t infos[4];
  int n = dds_take(reader, samples, infos, 4, 4);
  for (int i = 0; i < n; i++) {
    const viscera_SceneInfo *si = samples[i];
    if (!infos[i].valid_data || !seat_server_scene(&h->server, reader, &infos[i], si)) continue;
    uint32_t t = h->slot.tool_id;
    if (t < si->tools._length)
      feedback_slot_set_limits(&h->slot, si->tools._buffer[t].stiffness, si->tools._buffer[t].max_force);
    if (atomic_load(&h->scenes) == 0) {
      snprintf(h->scene_name, sizeof h->scene_name, "%s", si->scene);
      h->scene_tools = si->tools._length;
    }
    atomic_fetch_add(&h->scenes, 1);
  }
  if (n > 0) dds_return_loan(reader, samples, n);
}

int haptic_dds_open(haptic_dds_t *h, const haptic_options_t *o, size_t latency_capacity) {
  verr_t err;
  vdds_set_tool((int)o->tool);
  vdds_set_station(o->station); /* in the participant's USER_DATA too: recordings name who drove */
  if (vdds_open(&h->dds, o->domain, o->partition, &err)) {
    fprintf(stderr, "viscera-haptic: %s\n", err.msg);
    return 1;
  }
  h->w_cmd = vdds_writer_station(&h->dds, VT_TOOL_COMMAND, o->station, &err);
  if (feedback_slot_init(&h->slot, o->tool, latency_capacity)) {
    fprintf(stderr, "viscera-haptic: out of memory\n");
    vdds_close(&h->dds);
    return 1;
  }
  if (seat_server_open(&h->server, h->dds.participant, &err)) {
    fprintf(stderr, "viscera-haptic: %s\n", err.msg);
    vdds_close(&h->dds);
    feedback_slot_destroy(&h->slot);
    return 1;
  }
  h->slot.server = &h->server;
  h->r_fb = feedback_slot_attach(&h->slot, &h->dds, &err);
  dds_listener_t *l = dds_create_listener(h);
  dds_lset_data_available(l, on_scene);
  h->r_scene = vdds_reader_listener(&h->dds, VT_SCENE_INFO, l, &err);
  dds_delete_listener(l);
  if (guide_slot_init(&h->guide, o->tool)) {
    fprintf(stderr, "viscera-haptic: cannot initialise the guide slot\n");
    vdds_close(&h->dds);
    feedback_slot_destroy(&h->slot);
    seat_server_close(&h->server);
    return 1;
  }
  h->guide.server = &h->server; /* ToolRole from the seat's server only */
  if (h->w_cmd < 0 || h->r_fb < 0 || h->r_scene < 0 || guide_slot_attach(&h->guide, &h->dds, h->w_cmd, &err)) {
    fprintf(stderr, "viscera-haptic: %s\n", err.msg);
    haptic_dds_close(h);
    return 1;
  }
  return 0;
}

/* 1 once the seat's server's SceneInfo was adopted (said once). */
static int take_scene(haptic_dds_t *h, const haptic_options_t *o) {
  if (atomic_load(&h->scenes) == 0) return 0;
  if (!o->quiet)
    fprintf(stderr, "haptic: scene '%s', %u tool(s); driving tool %u\n", h->scene_name, h->scene_tools, o->tool);
  if (o->tool >= h->scene_tools)
    fprintf(stderr, "haptic: warning: tool %u is not in the scene; the server will reject its commands\n", o->tool);
  return 1;
}

int haptic_dds_wait_scene(haptic_dds_t *h, const haptic_options_t *o, volatile sig_atomic_t *stop) {
  uint64_t wait_until = vtime_mono_ns() + (uint64_t)(o->wait_server * 1e9);
  while (!*stop && vtime_mono_ns() < wait_until) {
    if (take_scene(h, o)) return 1;
    dds_sleepfor(DDS_MSECS(5));
  }
  if (!*stop)
    fprintf(stderr, "viscera-haptic: no server answered within %.1f s (domain %d, partition '%s')\n", o->wait_server,
            o->domain, o->partition ? o->partition : VDDS_DEFAULT_PARTITION);
  return 0;
}

void haptic_dds_close(haptic_dds_t *h) {
  vdds_close(&h->dds); /* stops the listener before the slot goes */
  feedback_slot_destroy(&h->slot);
  guide_slot_destroy(&h->guide);
  seat_server_close(&h->server);
}
