/* SPDX-License-Identifier: Apache-2.0 */
/* passivity: a time-domain passivity observer and controller on one
 * impedance port (docs/remote.md; Hannaford and Ryu, "Time-domain
 * passivity control of haptic interfaces", 2002). Pure arithmetic, no
 * clock, no allocation: the 1 kHz loop calls it and unit tests check it.
 *
 * The port is the device: the loop measures the hand's displacement dx over
 * each tick (and its velocity v = dx / dt) and renders a force f (N) on the
 * hand, held until the next tick. The observer sums the work the rendering
 * did on the hand,
 *   E(n) = sum_{i <= n} f(i - 1) . dx(i)   (J),
 * the force held during the tick times the hand's displacement in it (exact
 * for a force held over the tick, whatever the tick's length), so E <= 0 at
 * every tick means the rendered environment has given back no more than the
 * hand put in: passive.
 *
 * The controller. A force whose change per tick is bounded (contact_render.c
 * ramps every change) cannot be withdrawn at once: a force f rendered now
 * keeps doing work while it is released, f, f - r, f - 2r, ... (r the
 * release step per tick). Predicting one tick ahead and then lowering the
 * force at the ramp's rate leaves that tail unbudgeted, and a hand that
 * accelerates away from the wall makes it larger still (issue 14: 5-54 uJ
 * and 0.23 mJ above zero). So the controller budgets the whole release
 * before it lets a force through: with u_k the hand's speed along the force
 * k ticks ahead (its velocity plus its acceleration, when it grows, for
 * the ticks until then) and tau the ticks' length (T, or the longest tick
 * of late: a loaded machine's late tick holds the force longer), the
 * energy still owed by rendering |f| = m now is
 *   W(m) = m max(u_0, 0) h + sum_{k >= 1, m - k r > 0} (m - k r) max(u_k, 0) tau,
 * h >= tau the longest the force now may be held (a reserve for this very
 * tick being late, which no history predicts),
 * and the force passed is the largest m' <= m along f's own line with
 * E + W(m') <= 0. Its dissipative element is that scaling (the variable
 * damper alpha v of Ryu and Hannaford, along the force's line, that never
 * reverses the force: it stops at zero rather than pull the hand into a
 * wall). The caller lets the force fall faster than its ramp when the
 * controller asks (contact_render.h: CONTACT_RENDER_PASSIVE_STEP), which
 * leaves a margin for what the prediction misses.
 *
 * The late-model credit (issue 14; docs/remote.md). E <= 0 alone cannot
 * render a contact model that reaches the client after the hand has
 * stopped inside the tissue: the hand did the work of that press on the
 * server's tissue while the client rendered nothing, E is 0, and any force
 * on a hand that is not perfectly still is withheld. So the bound is
 * passivity with respect to the rendered spring's stored energy:
 *   E(n) <= C(n),   C = sum over contact episodes e of c_e   (J),
 *   c_e = max over the episode's ticks t of [ U(t) - B_e(t) ]^+,
 *   U(t) = |F(t)|^2 / (2 k(t)),
 *   B_e(t) = max over its ticks s <= t of (E(start of e) - E(s)),
 * F the force the renderer asks the controller for that tick (the model's
 * force at the hand, after the ramp: a model that jumps for a tick holds
 * no more than the ramp lets through), k the model's (device-clamped)
 * stiffness: U is the
 * energy held by the server's own proxy spring while it pushes with |F|,
 * the least any spring of stiffness <= k holds at that force, and so at
 * most f_max^2 / (2 k). B_e is the most energy the hand has put in through
 * this port during the episode: a press rendered as it went has paid for
 * its spring (B_e >= U) and gets nothing; a press whose model arrived late
 * gets the difference. c_e is a maximum, never a sum: re-anchors, new
 * samples, flapping contact within the episode re-evaluate one number,
 * bounded by f_max^2 / (2 k). The caller (contact_render.h) opens an
 * episode at a press's first pushing model and closes it only when the
 * press is over and the hand is back out of the spring it was credited
 * for, so a credit is granted again only after the hand has left and
 * pressed again. The controller holds E + W <= C. */
#ifndef VISCERA_PASSIVITY_H
#define VISCERA_PASSIVITY_H

#include <stdint.h>

typedef struct passivity {
  double period_s;   /* T, the nominal tick */
  double energy;     /* E, J: <= credit is passive */
  double energy_max; /* largest E seen after a tick, J (starts at 0) */
  double credit;     /* C, J: the late-model credits granted (sum of closed and open episodes' c_e) */
  double excess_max; /* largest E - C seen after a tick, J (starts at 0): <= 0 is passive */
  int episode;       /* an episode is open */
  double ep_start;   /* E when it opened, J */
  double ep_banked;  /* B_e, J */
  double ep_credit;  /* c_e, J (included in credit) */
  /* m/s: the release is budgeted for a hand leaving at least this fast (0:
   * as predicted). A hand at rest predicts no work, so without it a force
   * could be rendered on a resting hand with no budget left, and the hand's
   * first move out would then do the release's work unpaid. */
  double release_floor;
  double dissipated; /* J of predicted work the controller withheld */
  uint64_t active_ticks;
} passivity_t;

void passivity_init(passivity_t *p, double period_s);

/* The energy (J) a force of magnitude m rendered now and then released at
 * release_step (N per tick) is predicted to put into a hand moving at u
 * (m/s, along the force; > 0 away from the wall) with acceleration a
 * (m/s^2, along the force; only a growth of u counts): the force is held
 * now for hold_s (>= tick_s: the reserve for this tick being late), then
 * released in ticks of tick_s, during which (and over this tick) the hand
 * is taken to leave at u_floor (m/s) at least (0: as predicted). */
double passivity_owed(double m, double u, double a, double tick_s, double hold_s, double release_step, double u_floor);

/* The controller: f (in place) scaled down along its line, the least, so
 * that E + passivity_owed(|f|, ...) <= C (zero when even that cannot hold
 * E: then nothing more is put in). v the hand's velocity, a its
 * acceleration (m/s^2), tick_s the tick's length to budget (>= T), hold_s
 * the longest this tick may last. Returns the scale (1: unchanged). Does
 * not update E. */
double passivity_control(passivity_t *p, const double v[3], const double a[3], double tick_s, double hold_s,
                         double release_step, double f[3]);

/* The late-model credit: opens an episode (no-op when one is open). */
void passivity_episode_open(passivity_t *p);

/* Closes the open episode; its credit stays in C. */
void passivity_episode_close(passivity_t *p);

/* In an open episode, the stored energy U (J) of the model's spring this
 * tick: raises c_e (and C) to U - B_e when that is larger. Returns the
 * raise (J; 0 when none or no episode is open). */
double passivity_credit(passivity_t *p, double stored_j);

/* The stored energy of a spring of stiffness k (N/m) pushing with force f (N),
 * f^2 / (2 k) (J; 0 for k <= 0 or a force that is not finite). */
double passivity_spring_energy(double f, double k);

/* The observer: the force f was held while the hand moved by dx (m). */
void passivity_observe(passivity_t *p, const double f[3], const double dx[3]);

#endif
