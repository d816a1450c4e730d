/* SPDX-License-Identifier: Apache-2.0 */
#include "haptic_loop.h"

#include <math.h>
#include <pthread.h>
#include <string.h>

#include "contact_model.h"
#include "contact_render.h"
#include "guide_force.h"
#include "viscera.h"
#include "vmath.h"
#include "vtime.h"

/* State carried from tick to tick. */
typedef struct tick_state {
  contact_model_t model;
  const char *own_station;
  double prev_pos[3];
  uint64_t prev_pos_ns;
  int have_prev_pos;
  uint64_t seq;
  int server_lost_reported;
  uint64_t live_lost_reported_ns;
  int cut;                 /* this tick: the server is lost, zero the force at once */
  int stale;               /* no feedback for CONTACT_RENDER_HOLD_S: the model ramps out */
  contact_render_t render; /* re-anchoring, ramp, passivity (contact_render.h) */
  double rtt_s;            /* smoothed command->feedback round trip, s */
  size_t rtt_samples;
} tick_state_t;

/* The device's pose as this tick's ToolCommand. */
static void send_command(const haptic_loop_t *l, tick_state_t *s, uint64_t now, const double pos[3],
                         const double quat[4], uint32_t buttons) {
  viscera_ToolCommand cmd;
  memset(&cmd, 0, sizeof cmd);
  cmd.tool_id = l->o->tool;
  cmd.seq = ++s->seq;
  cmd.client_mono_ns = now;
  for (int k = 0; k < 3; k++) cmd.position[k] = (float)pos[k];
  for (int k = 0; k < 4; k++) cmd.orientation[k] = (float)quat[k];
  cmd.buttons = buttons;
  cmd.max_force = (float)l->dev->max_force;
  /* before the write: the echo may beat it back */
  feedback_slot_sent_at(&l->h->slot, cmd.seq, cmd.client_mono_ns, pos);
  contact_render_sent(&s->render, cmd.seq, pos);
  dds_write(l->h->w_cmd, &cmd);
}

/* The latest contact model, and whether to render it (contact_render.h):
 * cut when the server is lost by liveliness (its process is gone or
 * unreachable for a whole lease, vdds.h), stale when it is alive but has
 * sent nothing for CONTACT_RENDER_HOLD_S (a slow or lossy link, a stalled
 * server: the model is held, then ramped out, never a "server lost").
 * Returns the monotonic time of the last feedback (0: none yet). */
static uint64_t read_feedback(const haptic_loop_t *l, tick_state_t *s, double t, uint64_t now) {
  uint64_t last_fb_mono = feedback_slot_read(&l->h->slot, &s->model);
  uint64_t lost_ns = 0, lost_last = 0;
  int lost_live = feedback_slot_server_lost(&l->h->slot, &lost_ns, &lost_last);
  /* The listener stamps arrivals after this tick's clock read now and then. */
  int fresh = last_fb_mono && (now <= last_fb_mono || now - last_fb_mono < (uint64_t)(CONTACT_RENDER_HOLD_S * 1e9));
  if (s->server_lost_reported && !lost_live && fresh && last_fb_mono > lost_ns) {
    fprintf(stderr, "haptic: t=%.3f s server back, force ramps back to the tissue's\n", t);
    s->server_lost_reported = 0;
  }
  /* A server that died sent its last feedback a whole lease before its
   * loss is heard. A loss heard within half a lease of the last feedback,
   * or with feedback arriving after it, is this process starved past the
   * lease (its own stall, a loaded machine): the samples were waiting in
   * the socket. Then the model stays (no cut, no "server lost"), as the
   * server keeps a client whose commands kept coming (liveliness_watch.h). */
  int starved = lost_live && lost_last &&
                (lost_ns - lost_last < (uint64_t)VDDS_FEEDBACK_LEASE_MS * 500000ull || last_fb_mono > lost_ns);
  if (starved && lost_ns != s->live_lost_reported_ns) {
    s->live_lost_reported_ns = lost_ns;
    l->st->liveliness_blips++;
    if (!l->o->quiet && l->st->liveliness_blips <= 3)
      fprintf(stderr,
              "haptic: t=%.3f s server liveliness lapsed %.0f ms after its last feedback (this process stalled?); "
              "kept\n",
              t, (double)(lost_ns - lost_last) * 1e-6);
  }
  s->cut = lost_live && !starved;
  if (s->cut) {
    s->model.in_contact = 0;
    if (lost_ns != s->live_lost_reported_ns) {
      s->live_lost_reported_ns = lost_ns;
      fprintf(stderr,
              "haptic: t=%.3f s server lost (liveliness lost, last feedback %.0f ms before, lease %d ms), force set "
              "to zero\n",
              t, lost_last ? (double)(lost_ns - lost_last) * 1e-6 : -1.0, VDDS_FEEDBACK_LEASE_MS);
      s->server_lost_reported = 1;
      l->st->server_lost++;
    }
  }
  int stale = last_fb_mono && !fresh && !s->cut;
  if (stale && !s->stale) {
    l->st->feedback_stale++;
    if (!l->o->quiet)
      fprintf(stderr, "haptic: t=%.3f s no feedback for %.0f ms from a live server, force ramps out\n", t,
              CONTACT_RENDER_HOLD_S * 1e3);
  }
  s->stale = stale;
  if (stale) s->model.in_contact = 0;
  return last_fb_mono;
}

/* The round trip to a guiding peer (guide_force.h: the coupling's damping
 * grows with it): at least --guide-rtt, twice our own smoothed round trip
 * to the server (the peer's commands cross the same link when the server
 * sits at the peer's site), and twice the peer's commands' one-way transit
 * to us when known (guide_slot_transit: an instructor beside the server,
 * whose own round trip is near zero while the trainee is a link away). */
static double guide_rtt(const haptic_loop_t *l, tick_state_t *s, double peer_transit_s) {
  feedback_slot_t *fs = &l->h->slot;
  pthread_mutex_lock(&fs->lock);
  size_t n = fs->nlatency;
  double last_us = n ? fs->latency_us[n - 1] : 0;
  pthread_mutex_unlock(&fs->lock);
  if (n != s->rtt_samples) {
    s->rtt_samples = n;
    s->rtt_s = s->rtt_s > 0 ? s->rtt_s + 0.02 * (last_us * 1e-6 - s->rtt_s) : last_us * 1e-6;
  }
  double own = 2.0 * s->rtt_s, peer = peer_transit_s > 0 ? 2.0 * peer_transit_s : 0;
  double rtt = own > peer ? own : peer;
  l->st->guide_rtt_s = rtt > l->o->guide_rtt ? rtt : l->o->guide_rtt;
  return l->st->guide_rtt_s;
}

/* The force to render: guided or not, one force law (guide_force.h); a
 * server silent for GUIDE_SERVER_TIMEOUT_S ends the coupling too. */
static void render_force(const haptic_loop_t *l, tick_state_t *s, double t, uint64_t now, uint64_t last_fb_mono,
                         const double pos[3], guide_output_t *gout) {
  const haptic_options_t *o = l->o;
  /* Device velocity by backward difference over the actual tick. */
  double vel[3] = {0, 0, 0}, moved[3] = {0, 0, 0};
  if (s->have_prev_pos) v3_sub(moved, pos, s->prev_pos);
  if (s->have_prev_pos && now > s->prev_pos_ns)
    for (int k = 0; k < 3; k++) vel[k] = moved[k] / ((double)(now - s->prev_pos_ns) * 1e-9);
  memcpy(s->prev_pos, pos, sizeof s->prev_pos);
  s->prev_pos_ns = now;
  s->have_prev_pos = 1;
  /* Device capability data: never render a wall stiffer than the device
   * is rated for (its damping follows the clamped stiffness). */
  s->model.stiffness = contact_model_device_stiffness(s->model.stiffness, l->dev->max_stiffness);
  s->model.damping = contact_model_passive_damping(s->model.stiffness, 1.0 / o->rate);
  guide_view_t gv;
  guide_slot_read(&l->h->guide, s->own_station, now, &gv);
  guide_input_t gin = {.role = &gv.role,
                       .own_station = s->own_station,
                       .have_peer = gv.have_peer,
                       .peer_age_s = gv.peer_age_s,
                       .server_silent_s = !last_fb_mono        ? -1.0
                                          : now > last_fb_mono ? (double)(now - last_fb_mono) * 1e-9
                                                               : 0.0,
                       .contact = &s->model,
                       .max_force = l->dev->max_force,
                       .max_stiffness = l->dev->max_stiffness,
                       .period_s = 1.0 / o->rate,
                       .rtt_s = guide_rtt(l, s, gv.peer_transit_s),
                       .render = &s->render};
  memcpy(gin.x, pos, sizeof gin.x);
  memcpy(gin.v, vel, sizeof gin.v);
  memcpy(gin.peer, gv.peer, sizeof gin.peer);
  guide_force(&gin, gout);
  /* Coupled, the server answers this tick's command at the tool it mixes
   * from both hands: the ring keeps our prediction of it (guide_force.h). */
  if (gout->coupled) contact_render_sent(&s->render, s->seq, gout->x_tool);
  /* Uncoupled, the contact model re-anchored at our own position; coupled,
   * the guiding law's force (its contact part re-anchored at the tool).
   * Either way ramped and observed. */
  double target[3];
  if (gout->coupled)
    memcpy(target, gout->f, sizeof target);
  else
    contact_render_target(&s->render, s->cut ? NULL : &s->model, pos, vel, target);
  gout->magnitude = contact_render_output(&s->render, target, s->cut, !gout->coupled, vel, moved, gout->f);
  guide_report_tick(l->guide, t, &gv.role, gv.peer_station, gv.peer_age_s, gout, o->quiet ? NULL : stderr);
}

/* The rendered force in the statistics and the CSV. */
static void record_force(const haptic_loop_t *l, const tick_state_t *s, double t, const double pos[3],
                         const guide_output_t *gout) {
  haptic_stats_t *st = l->st;
  const double *f = gout->f, mag = gout->magnitude;
  st->ticks++;
  /* In contact: the tissue pushes (a guiding spring in free space is not
   * contact; unguided, mag > 0 only in contact anyway). */
  if (mag > 0 && s->model.in_contact) {
    st->contact_ticks++;
    st->force_sum += mag;
  }
  if (mag > st->peak_force) st->peak_force = mag;
  st->energy_max_j = s->render.pc.energy_max;
  st->energy_j = s->render.pc.energy;
  st->credit_j = s->render.pc.credit;
  st->excess_max_j = s->render.pc.excess_max;
  st->stall_energy_j = s->render.stall_energy;
  st->energy_max_unstalled_j = s->render.energy_max_unstalled;
  st->stall_ticks = s->render.stall_ticks;
  st->step_max_n = s->render.step_max;
  if (l->csv)
    fprintf(l->csv, "%.4f,%.6f,%.6f,%.6f,%.5f,%.5f,%.5f,%d,%.7f,%.5f\n", t, pos[0], pos[1], pos[2], f[0], f[1], f[2],
            s->model.in_contact, s->render.pc.energy, s->render.step_tick);
}

void haptic_loop_run(const haptic_loop_t *l) {
  const haptic_options_t *o = l->o;
  haptic_stats_t *st = l->st;
  tick_state_t s; /* 33 kB with the renderer's position ring: on the loop thread's stack */
  memset(&s, 0, sizeof s);
  s.own_station = o->station ? o->station : "";
  contact_render_init(&s.render, 1.0 / o->rate, l->dev->max_force);
  uint64_t period_ns = (uint64_t)(1e9 / o->rate);
  double run_for = o->duration >= 0 ? o->duration : 1e300;
  uint64_t start = vtime_mono_ns(), next = start, prev_tick = 0;
  /* The device's clock (a scripted path's time): from the loop's start, or
   * with --start-on-answer from the server's first answer (0 until then:
   * the path's first pose), so that the start of a path is not lost while
   * the server's reader has yet to match this writer. */
  uint64_t dev_start = o->start_on_answer ? 0 : start, last_fb_mono = 0;
  st->script_start_s = o->start_on_answer ? -1.0 : 0.0;
  double finished_at = -1;
  while (!*l->stop) {
    vtime_sleep_until(next);
    uint64_t now = vtime_mono_ns();
    double t = (double)(now - start) * 1e-9;
    if (!dev_start && (last_fb_mono || t >= o->wait_server)) {
      dev_start = now;
      st->script_start_s = t;
      if (!last_fb_mono)
        fprintf(stderr, "haptic: warning: no answer from the server within %.1f s: the path starts without one\n",
                o->wait_server);
    }
    double td = dev_start ? (double)(now - dev_start) * 1e-9 : 0.0;
    if (prev_tick) {
      if (st->nperiod < st->cap) st->period_us[st->nperiod++] = (double)(now - prev_tick) * 1e-3;
      if (now > next + 1000000ull) st->late_ticks++; /* more than 1 ms late */
    }
    prev_tick = now;
    double pos[3], quat[4];
    uint32_t buttons = 0;
    l->dev->ops->read(l->dev, td, pos, quat, &buttons);
    send_command(l, &s, now, pos, quat, buttons);
    last_fb_mono = read_feedback(l, &s, t, now);
    guide_output_t gout;
    render_force(l, &s, t, now, last_fb_mono, pos, &gout);
    l->dev->ops->write_force(l->dev, gout.f);
    record_force(l, &s, t, pos, &gout);

    if (t >= run_for) break;
    if (o->duration < 0 && dev_start && l->dev->ops->finished(l->dev, td)) {
      if (finished_at < 0) finished_at = t;
      if (t - finished_at > 0.5) break;
    }
    next += period_ns;
    if (now > next + 100000000ull) next = now; /* resynchronise after a long stall */
  }
  if (l->csv) fclose(l->csv);
  st->pc_ticks = s.render.pc.active_ticks;
  st->reanchored_ticks = s.render.reanchored_ticks;
  st->plain_ticks = s.render.plain_ticks;
  st->unplaced_ticks = s.render.unplaced_ticks;
  st->cuts = s.render.cuts;
  st->elapsed_s = (double)(vtime_mono_ns() - start) * 1e-9;
}
