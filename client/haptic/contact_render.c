/* SPDX-License-Identifier: Apache-2.0 */
#include "contact_render.h"

#include <math.h>
#include <string.h>

#include "vmath.h"

void contact_render_init(contact_render_t *r, double period_s, double max_force) {
  memset(r, 0, sizeof *r);
  r->period_s = period_s;
  r->max_step = CONTACT_RENDER_MAX_STEP;
  r->max_force = max_force;
  r->tick_s = period_s;
  passivity_init(&r->pc, period_s);
  r->pc.release_floor = CONTACT_RENDER_RELEASE_FLOOR;
}

void contact_render_sent(contact_render_t *r, uint64_t seq, const double x[3]) {
  size_t i = seq % CONTACT_RENDER_RING;
  r->ring_seq[i] = seq;
  v3_copy(r->ring_x[i], x);
  if (seq > r->sent_seq) r->sent_seq = seq;
}

/* Where our command `seq` put the hand; 0 when it is no longer known. */
static int sent_position(const contact_render_t *r, uint64_t seq, double x[3]) {
  size_t i = seq % CONTACT_RENDER_RING;
  if (seq == 0 || r->ring_seq[i] != seq) return 0;
  v3_copy(x, r->ring_x[i]);
  return 1;
}

double contact_render_target(contact_render_t *r, const contact_model_t *m, const double x[3], const double v[3],
                             double f[3]) {
  v3_set(f, 0, 0, 0);
  /* For the late-model credit of the next contact_render_output. */
  r->target_set = 1;
  r->target_k = m && m->in_contact ? m->stiffness : 0;
  v3_copy(r->target_x, x);
  if (!m || !m->in_contact) {
    /* A press's anchor outlives a short gap in contact (the server's proxy
     * let go for a few steps while the tissue moved away faster than the
     * hand): re-anchoring mid-press at a deep proxy would take the tool's
     * stiffness for the organ's and overshoot. */
    if (r->anchored && ++r->off_ticks * r->period_s > CONTACT_RENDER_HOLD_S) {
      r->anchored = 0;
      r->lag = 0;
    }
    return 0;
  }
  r->off_ticks = 0;
  const double *n = m->normal;
  double k = m->stiffness;
  double x_cmd[3];
  int placed = sent_position(r, m->cmd_seq, x_cmd), known = placed;
  if (placed)
    r->lag = r->sent_seq >= m->cmd_seq ? r->sent_seq - m->cmd_seq + 1 : 0;
  else if (r->lag && r->anchored && r->sent_seq >= r->lag)
    known = sent_position(r, r->sent_seq - r->lag + 1, x_cmd); /* as old as the last placed answer */
  double d_cmd[3];
  v3_sub(d_cmd, m->proxy, known ? x_cmd : x);
  double spring = k * v3_dot(d_cmd, n); /* the server's proxy spring at x_cmd */
  if (!r->anchored) {
    /* The press begins: its surface point, and no extrapolation until the
     * press is deep enough to measure the organ's stiffness. A press that
     * begins with the hand already inside (the server back after a blip)
     * has no surface point: it is never extrapolated. */
    v3_copy(r->onset, m->proxy);
    r->onset_spring = spring;
    r->k_eff = 0;
    r->anchored = 1;
  }
  if (!known) {
    r->plain_ticks++;
    return contact_model_force(m, x, v, r->max_force, f);
  }
  r->reanchored_ticks++;
  if (!placed) r->unplaced_ticks++;
  double d_onset[3];
  v3_sub(d_onset, r->onset, x_cmd);
  double depth = v3_dot(d_onset, n); /* x_cmd below where the press began */
  if (placed && depth > CONTACT_RENDER_MIN_DEPTH && spring > 0 && r->onset_spring < CONTACT_RENDER_ONSET_SPRING) {
    double k_sec = fmin(k, spring / depth);
    r->k_eff += (k_sec - r->k_eff) * fmin(1.0, r->period_s / CONTACT_RENDER_K_TAU);
  }
  if (r->k_eff > k) r->k_eff = k; /* the stiffness may drop mid-press */
  double moved[3];
  v3_sub(moved, x_cmd, x);
  double mag = spring + r->k_eff * v3_dot(moved, n);
  if (v) mag -= m->damping * v3_dot(v, n);
  if (!(mag > 0)) return 0; /* never pull into the wall; NaN renders nothing */
  if (mag > r->max_force) mag = r->max_force;
  v3_scale(f, n, mag);
  return mag;
}

/* The hand's filtered acceleration and the tick length to budget, from
 * this tick's velocity v and displacement dx (dt = |dx| / |v|). Returns dt. */
static double track_motion(contact_render_t *r, const double v[3], const double dx[3]) {
  double T = r->period_s, vn = v3_norm(v), dt = vn > 1e-9 ? v3_norm(dx) / vn : T;
  if (!(dt > 0) || !isfinite(dt)) dt = T;
  r->tick_s = T + (r->tick_s - T) * exp(-dt / CONTACT_RENDER_TICK_MEMORY);
  if (dt > r->tick_s) r->tick_s = fmin(dt, CONTACT_RENDER_TICK_MAX);
  if (r->have_v && v3_isfinite(v)) {
    double a[3], w = fmin(1.0, dt / CONTACT_RENDER_ACCEL_TAU);
    v3_sub(a, v, r->v_prev);
    v3_scale(a, a, 1.0 / dt);
    for (int k = 0; k < 3; k++) r->accel[k] += w * (a[k] - r->accel[k]);
  }
  if (v3_isfinite(v)) {
    v3_copy(r->v_prev, v);
    r->have_v = 1;
  }
  return dt;
}

/* Moves f_prev towards g by at most `step` (N) and returns the result in f. */
static void ramp(const double f_prev[3], const double g[3], double step, double f[3]) {
  double d[3];
  v3_sub(d, g, f_prev);
  double n = v3_norm(d);
  if (n > step) v3_scale(d, d, step / n);
  v3_add(f, f_prev, d);
}

/* The late-model credit's episode (contact_render.h, passivity.h): g the
 * force the ramp passes this tick towards the model's at the hand x, k the
 * model's stiffness. */
static void late_credit(contact_render_t *r, const double g[3], double k, const double x[3]) {
  double mag = v3_norm(g);
  int pushing = mag > 0 && k > 0 && isfinite(mag) && v3_isfinite(x);
  if (r->pc.episode && !r->credit_left && v3_isfinite(x)) {
    double out[3];
    v3_sub(out, x, r->credit_x);
    r->credit_left = r->pc.ep_credit <= 0 || v3_dot(out, r->credit_n) >= r->credit_len;
  }
  if (!pushing) {
    /* The press is over and the hand has left the credited spring since
     * it was credited: the next press is a new episode. */
    if (r->pc.episode && !r->anchored && r->credit_left) passivity_episode_close(&r->pc);
    return;
  }
  if (!r->pc.episode) {
    passivity_episode_open(&r->pc);
    r->credit_left = 1;
  }
  if (passivity_credit(&r->pc, passivity_spring_energy(mag, k)) > 0) {
    v3_copy(r->credit_x, x);
    v3_scale(r->credit_n, g, 1.0 / mag);
    r->credit_len = mag / k;
    r->credit_left = 0;
    r->credit_raises++;
  }
}

double contact_render_output(contact_render_t *r, const double target[3], int cut, int control, const double v[3],
                             const double dx[3], double f[3]) {
  int credit = control && r->target_set;
  r->target_set = 0;
  double before[3];
  v3_copy(before, r->f_prev);
  passivity_observe(&r->pc, r->f_prev, dx); /* last tick's force over the way the hand went since */
  if (track_motion(r, v, dx) > CONTACT_RENDER_STALL_S) {
    double de = v3_dot(r->f_prev, dx);
    if (isfinite(de)) r->stall_energy += de;
    r->stall_ticks++;
  }
  if (r->pc.energy - r->pc.credit - r->stall_energy > r->energy_max_unstalled)
    r->energy_max_unstalled = r->pc.energy - r->pc.credit - r->stall_energy;
  if (cut) {
    /* The server is gone: nothing to ramp towards, and a wall it no longer
     * computes must not stay under the hand. */
    v3_set(f, 0, 0, 0);
    if (v3_norm(r->f_prev) > 0) r->cuts++;
  } else {
    double g[3];
    v3_copy(g, target);
    if (!v3_isfinite(g)) v3_set(g, 0, 0, 0);
    double mag = v3_norm(g);
    if (mag > r->max_force) v3_scale(g, g, r->max_force / mag);
    /* The ramp first, then the controller on the force the hand will
     * actually get (and the release it commits to), then the ramp's bound
     * again, widened to CONTACT_RENDER_PASSIVE_STEP where the controller
     * asked for less. */
    ramp(r->f_prev, g, r->max_step, f);
    /* Credited for the force the ramp passes, not the target: a model that
     * jumps for a tick (a plain plane before the press is re-anchored)
     * holds no more than the ramp lets it render. */
    if (credit) late_credit(r, f, r->target_k, r->target_x);
    if (control && passivity_control(&r->pc, v, r->accel, r->tick_s, CONTACT_RENDER_STALL_S, r->max_step, f) < 1.0) {
      double h[3];
      v3_copy(h, f);
      ramp(r->f_prev, h, CONTACT_RENDER_PASSIVE_STEP, f);
    }
    double d[3];
    v3_sub(d, f, r->f_prev);
    double step = v3_norm(d);
    if (step > r->step_max) r->step_max = step;
  }
  v3_sub(before, f, before);
  r->step_tick = v3_norm(before);
  v3_copy(r->f_prev, f);
  return v3_norm(f);
}

double contact_render_tick(contact_render_t *r, const contact_model_t *m, int cut, const double x[3], const double v[3],
                           const double dx[3], double f[3]) {
  double target[3];
  contact_render_target(r, cut ? NULL : m, x, v, target);
  return contact_render_output(r, target, cut, 1, v, dx, f);
}
