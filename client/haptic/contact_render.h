/* SPDX-License-Identifier: Apache-2.0 */
/* contact_render: what the haptic client renders from a contact model that
 * is one network round trip old (docs/remote.md). Pure arithmetic, no
 * clock and no allocation: the 1 kHz loop and the delayed-feedback unit test
 * (tests/client/haptic/test_contact_render.c) run the same code.
 *
 * 1. Re-anchoring. A ContactFeedback answers one of our commands (cmd_seq):
 *    the server placed its proxy for the hand where it was then, x_cmd, and
 *    the tissue under the proxy has since kept deforming. The plain plane
 *    model k (p - x) . n renders the tool's stiffness k for the distance the
 *    hand moved since, although the server, pressing a soft organ, would
 *    let the proxy sink with it: an old plane overshoots (up to 2x at
 *    50 ms). So the force is the server's own spring at the command it
 *    answered plus the organ's effective stiffness for the way since:
 *      F = k (p - x_cmd) . n + k_eff (x_cmd - x) . n - b (v . n),
 *    k_eff the secant stiffness of the press (the server's force over the
 *    depth of x_cmd below the surface point where contact began, low-pass
 *    filtered, within [0, k]). With no delay x_cmd is the hand and F is the
 *    server's force; our positions are kept by command seq (a ring of
 *    CONTACT_RENDER_RING, 1 s at 1 kHz). A feedback answering a command we
 *    cannot place (no echo we sent, or a seq the ring no longer holds)
 *    within a press whose answers we could place is re-anchored at the
 *    command as old as the last placed one (the same lag behind our newest):
 *    rendered as the plain plane instead, the way moved since takes the
 *    tool's stiffness k (400 N/m) for the organ's (~120 N/m), and a hand
 *    that stopped one round trip after pressing got a spike (issue 14:
 *    1.166 N against 0.97 N at 50 ms, k x 0.5 mm for 3 ticks). A press
 *    with no placed answer at all (another station's) stays the plain
 *    plane. k_eff never exceeds the current sample's k (a stiffness that
 *    drops mid-press, e.g. the device's clamp).
 * 2. Ramping. Every change of model (contact begins or ends, a new sample
 *    after a gap, the server back) reaches the hand through a bound on the
 *    force's change per tick, max_step: no step is felt.
 * 3. Passivity. A time-domain passivity observer and controller
 *    (passivity.h) on the rendered force, after the ramp. The controller
 *    budgets the energy the ramped force will still deliver while it is
 *    released, for the hand's velocity and acceleration (filtered over
 *    CONTACT_RENDER_ACCEL_TAU) and the longest recent tick (a loaded
 *    machine's late tick holds the force longer), so E stays <= 0; when it
 *    asks for less force the ramp yields, up to CONTACT_RENDER_PASSIVE_STEP
 *    per tick.
 *    The late-model credit (passivity.h): a press whose model arrived
 *    after the hand had gone in (at worst after it stopped inside: the
 *    hand's work was done on the server's tissue while nothing was
 *    rendered) is credited the stored energy of the model's spring at the
 *    force it renders, less what the hand put in through this port in the
 *    press, |F|^2 / (2 k) - B, a running maximum per press. An episode
 *    opens at the press's first pushing model and closes only when the
 *    press is over (its anchor forgotten: no contact for
 *    CONTACT_RENDER_HOLD_S) and the hand has been back out of the credited
 *    spring (|F| / k along its normal from where it was credited) since
 *    the credit was last raised: the
 *    model flapping, re-anchoring or the server back after a blip cannot
 *    grant it again while the hand stays in.
 * 4. A stale model (no feedback for hold_s: the link is slow, lossy or the
 *    server stalls) is held, re-anchored at our own position, and then
 *    ramped to zero; only a cut (the server's liveliness lost: it is gone)
 *    zeroes the force within the tick.
 * The model's stiffness and damping are the caller's (device-clamped,
 * contact_model.h). */
#ifndef VISCERA_CONTACT_RENDER_H
#define VISCERA_CONTACT_RENDER_H

#include <stdint.h>

#include "contact_model.h"
#include "passivity.h"

#define CONTACT_RENDER_RING 1024
/* N: the largest change of the rendered force per tick (issue target 0.1 N). */
#define CONTACT_RENDER_MAX_STEP 0.08
/* N: how fast the force may fall when the passivity controller asks (the
 * budget assumes the ramp's max_step; the faster fall is the margin for an
 * acceleration the prediction did not see). Within the 0.1 N. */
#define CONTACT_RENDER_PASSIVE_STEP 0.095
/* s: the hand's acceleration (the controller's prediction) is low-pass
 * filtered over this: a scripted or sampled path jumps in velocity at its
 * samples, a spike the filter spreads without losing its mean. */
#define CONTACT_RENDER_ACCEL_TAU 0.005
/* s: a late tick is budgeted for this long after it (then decays to T), up
 * to CONTACT_RENDER_TICK_MAX: a longer stall is a stalled client, not a
 * tick to plan every release for (it would forbid any force). */
#define CONTACT_RENDER_TICK_MEMORY 0.2
#define CONTACT_RENDER_TICK_MAX 0.02
/* s: the controller's reserve for the tick now being late (a loaded
 * machine's loop, seen 1-65 ms at load 8): the force rendered now is budgeted as held
 * this long. A longer stall of the client's loop can leave a few uJ. */
#define CONTACT_RENDER_STALL_S 0.02
/* m/s: the controller budgets every release for a hand leaving at least
 * this fast (passivity.h release_floor): a hand that rests with the budget
 * spent, then starts out, left 17 uJ over it (test_contact_render's
 * flapping model). */
#define CONTACT_RENDER_RELEASE_FLOOR 0.002
/* s: how long a model is rendered without a new sample before it ramps out. */
#define CONTACT_RENDER_HOLD_S 0.25
/* m: the depth below which the press's secant stiffness is not estimated. */
#define CONTACT_RENDER_MIN_DEPTH 5e-4
/* s: time constant of the secant stiffness filter. */
#define CONTACT_RENDER_K_TAU 0.02
/* N: a press whose first sample already pushes this hard began inside the
 * organ (the server back after a blip): no surface point, no extrapolation. */
#define CONTACT_RENDER_ONSET_SPRING 0.1

typedef struct contact_render {
  double period_s, max_step, max_force;
  uint64_t ring_seq[CONTACT_RENDER_RING];
  double ring_x[CONTACT_RENDER_RING][3];
  uint64_t sent_seq;   /* our newest command */
  uint64_t lag;        /* commands between our newest and the one the last placed answer named (0: none this press) */
  int anchored;        /* the surface point where contact began is known */
  double onset[3];     /* that point */
  double onset_spring; /* N, the server's spring in the press's first sample */
  uint64_t off_ticks;  /* ticks without contact since the press's last sample */
  double k_eff;        /* N/m, the press's filtered secant stiffness */
  double f_prev[3];    /* force rendered last tick */
  double step_max;     /* N, the largest one-tick change rendered (cuts excluded) */
  double step_tick;    /* N, this tick's change */
  uint64_t cuts;       /* forces zeroed at once (server lost) */
  uint64_t reanchored_ticks, plain_ticks;
  uint64_t unplaced_ticks; /* of reanchored_ticks: an answer we could not place, at the last placed lag */
  double v_prev[3];        /* m/s, the hand's velocity last tick */
  double accel[3];         /* m/s^2, its filtered acceleration */
  double tick_s;           /* s, the tick length the controller budgets (recent longest) */
  int have_v;              /* v_prev holds a velocity */
  /* The work done over ticks longer than CONTACT_RENDER_STALL_S (the
   * client's loop stalled: no controller can act within them), J, and the
   * observer's largest value without it: what the controller answers for. */
  double stall_energy, energy_max_unstalled;
  uint64_t stall_ticks;
  /* The spring of the open episode's credit (its latest raise): where the
   * hand was, the force's unit normal, its length |F| / k (m). */
  double credit_x[3], credit_n[3], credit_len;
  int credit_left; /* the hand has been out of that spring since */
  /* Set by contact_render_target for the next contact_render_output: the
   * model's stiffness (0: no contact) and the hand's position. */
  int target_set;
  double target_k, target_x[3];
  uint64_t credit_raises; /* ticks that raised the credit */
  passivity_t pc;
} contact_render_t;

void contact_render_init(contact_render_t *r, double period_s, double max_force);

/* Our command `seq` put the hand at x. */
void contact_render_sent(contact_render_t *r, uint64_t seq, const double x[3]);

/* The model's force at hand position x and velocity v (before the ramp and
 * the passivity controller), into f; returns its magnitude. m NULL or not in
 * contact: zero (and the press's anchor is forgotten). */
double contact_render_target(contact_render_t *r, const contact_model_t *m, const double x[3], const double v[3],
                             double f[3]);

/* One tick: m the newest model (NULL: none usable, e.g. stale beyond
 * hold_s; the force ramps to zero), cut 1 when the server was lost (zero at
 * once), v the hand's velocity and dx its displacement since the last tick
 * (the passivity observer's input). Writes the force to render into f and
 * returns its magnitude. */
double contact_render_tick(contact_render_t *r, const contact_model_t *m, int cut, const double x[3], const double v[3],
                           const double dx[3], double f[3]);

/* Ramp and passivity for a target force: the same bounds and observer as
 * contact_render_tick. The late-model credit needs the model: only a
 * target from contact_render_target just before is credited (a controlled
 * target from elsewhere gets none: with nothing banked it is withheld).
 * control 0 observes without
 * the controller (the
 * guiding hand: a led hand must receive the energy its guide puts in, so
 * one port alone may not be held passive; guide_force.h damps the coupling
 * for the delay instead). */
double contact_render_output(contact_render_t *r, const double target[3], int cut, int control, const double v[3],
                             const double dx[3], double f[3]);

#endif
