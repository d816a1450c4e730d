#include "haptic_dds.h"

#include <stdio.h>

#include "viscera.h"
#include "vtime.h"

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
  h->r_fb = feedback_slot_attach(&h->slot, &h->dds, &err);
  h->r_scene = vdds_reader(&h->dds, VT_SCENE_INFO, &err);
  if (guide_slot_init(&h->guide, o->tool)) {
    fprintf(stderr, "viscera-haptic: cannot initialise the guide slot\n");
    vdds_close(&h->dds);
    feedback_slot_destroy(&h->slot);
    return 1;
  }
  if (h->w_cmd < 0 || h->r_fb < 0 || h->r_scene < 0 || guide_slot_attach(&h->guide, &h->dds, h->w_cmd, &err)) {
    fprintf(stderr, "viscera-haptic: %s\n", err.msg);
    haptic_dds_close(h);
    return 1;
  }
  return 0;
}

/* Takes one SceneInfo sample if there is one: 1 when it was valid data. */
static int take_scene(haptic_dds_t *h, const haptic_options_t *o) {
  void *samples[1] = {0};
  dds_sample_info_t info;
  int n = dds_take(h->r_scene, samples, &info, 1, 1), have_scene = 0;
  if (n <= 0) return 0;
  const viscera_SceneInfo *si = samples[0];
  if (info.valid_data) {
    have_scene = 1;
    if (!o->quiet)
      fprintf(stderr, "haptic: scene '%s', %u tool(s); driving tool %u\n", si->scene, si->tools._length, o->tool);
    if (o->tool >= si->tools._length)
      fprintf(stderr, "haptic: warning: tool %u is not in the scene; the server will reject its commands\n", o->tool);
  }
  dds_return_loan(h->r_scene, samples, n);
  return have_scene;
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
}
