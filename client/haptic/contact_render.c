/* SPDX-License-Identifier: Apache-2.0 */
#include "contact_render.h"

#include <math.h>
#include <string.h>

#include "vmath.h"

void contact_render_init(contact_render_t *r, double period_s, double max_force, double max_damping) {
  memset(r, 0, sizeof *r);
  r->period_s = period_s;
  r->max_step = CONTACT_RENDER_MAX_STEP;
  r->max_force = max_force;
  passivity_init(&r->pc, period_s, max_damping);
}

void contact_render_sent(contact_render_t *r, uint64_t seq, const double x[3]) {
  size_t i = seq % CONTACT_RENDER_RING;
  r->ring_seq[i] = seq;
  v3_copy(r->ring_x[i], x);
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
  if (!m || !m->in_contact) {
    /* A press's anchor outlives a short gap in contact (the server's proxy
     * let go for a few steps while the tissue moved away faster than the
     * hand): re-anchoring mid-press at a deep proxy would take the tool's
     * stiffness for the organ's and overshoot. */
    if (r->anchored && ++r->off_ticks * r->period_s > CONTACT_RENDER_HOLD_S) r->anchored = 0;
    return 0;
  }
  r->off_ticks = 0;
  const double *n = m->normal;
  double k = m->stiffness;
  double x_cmd[3];
  int known = sent_position(r, m->cmd_seq, x_cmd);
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
  double d_onset[3];
  v3_sub(d_onset, r->onset, x_cmd);
  double depth = v3_dot(d_onset, n); /* x_cmd below where the press began */
  if (depth > CONTACT_RENDER_MIN_DEPTH && spring > 0 && r->onset_spring < CONTACT_RENDER_ONSET_SPRING) {
    double k_sec = fmin(k, spring / depth);
    r->k_eff += (k_sec - r->k_eff) * fmin(1.0, r->period_s / CONTACT_RENDER_K_TAU);
  }
  double moved[3];
  v3_sub(moved, x_cmd, x);
  double mag = spring + r->k_eff * v3_dot(moved, n);
  if (v) mag -= m->damping * v3_dot(v, n);
  if (!(mag > 0)) return 0; /* never pull into the wall; NaN renders nothing */
  if (mag > r->max_force) mag = r->max_force;
  v3_scale(f, n, mag);
  return mag;
}

double contact_render_output(contact_render_t *r, const double target[3], int cut, int control, const double v[3],
                             const double dx[3], double f[3]) {
  double before[3];
  v3_copy(before, r->f_prev);
  passivity_observe(&r->pc, r->f_prev, dx); /* last tick's force over the way the hand went since */
  if (cut) {
    /* The server is gone: nothing to ramp towards, and a wall it no longer
     * computes must not stay under the hand. */
    v3_set(f, 0, 0, 0);
    if (v3_norm(r->f_prev) > 0) r->cuts++;
  } else {
    double g[3];
    v3_copy(g, target);
    if (!v3_isfinite(g)) v3_set(g, 0, 0, 0);
    /* Released at max_step per tick, a force f still delivers about
     * (f . v) T (|f| / (2 max_step) + 1) after the controller asks for
     * less: the ramp's ticks, and the tick the force is held before the
     * observer sees it. */
    double fv = v3_dot(g, v);
    double reserve = fv > 0 ? fv * r->period_s * (v3_norm(g) / (2 * r->max_step) + 1.0) : 0;
    if (control) passivity_control(&r->pc, v, r->max_force, reserve, g);
    double d[3];
    v3_sub(d, g, r->f_prev);
    double step = v3_norm(d);
    if (step > r->max_step) v3_scale(d, d, r->max_step / step);
    v3_add(f, r->f_prev, d);
    double mag = v3_norm(f);
    if (mag > r->max_force) v3_scale(f, f, r->max_force / mag);
    v3_sub(d, f, r->f_prev);
    step = v3_norm(d);
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
