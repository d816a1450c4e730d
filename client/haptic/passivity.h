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
 * hand put in: passive. When the force about to be rendered would make E
 * positive over the next tick (E + f . v T), the controller adds a variable
 * damper
 *   f' = f - alpha v,  alpha = E_pred / (T |v|^2),
 * the damping that dissipates exactly the excess, bounded by the device's
 * damping limit (max_damping) and its force limit, and never reversing the
 * force (it stops at zero rather than pull the hand into a wall). A bounded
 * damper may leave E above zero for some ticks; the excess is carried and
 * dissipated on the following ticks (energy_max reports the worst). */
#ifndef VISCERA_PASSIVITY_H
#define VISCERA_PASSIVITY_H

#include <stdint.h>

typedef struct passivity {
  double period_s;    /* T */
  double max_damping; /* N s/m, the controller's damper bound */
  double energy;      /* E, J: <= 0 is passive */
  double energy_max;  /* largest E seen after a tick, J (starts at 0) */
  double dissipated;  /* J removed by the controller */
  uint64_t active_ticks;
} passivity_t;

void passivity_init(passivity_t *p, double period_s, double max_damping);

/* The controller: the force f (in place) corrected so that rendering it at
 * velocity v keeps E + reserve <= 0 where the damper bound allows; |f|
 * stays within max_force. reserve (J, >= 0) is energy the caller will
 * still deliver whatever the controller asks now (a rate-limited force
 * cannot drop at once: contact_render.c), so the damper starts early
 * enough. Returns the damping used (0 when none). Does not update E. */
double passivity_control(passivity_t *p, const double v[3], double max_force, double reserve, double f[3]);

/* The observer: the force f was held while the hand moved by dx (m). */
void passivity_observe(passivity_t *p, const double f[3], const double dx[3]);

#endif
