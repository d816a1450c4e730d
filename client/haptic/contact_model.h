/* SPDX-License-Identifier: Apache-2.0 */
/* contact_model: the local force model the haptic client renders at 1 kHz
 * from the latest ContactFeedback: a plane through the proxy with outward
 * normal n, stiffness k and damping b:
 *   F = max(0, k d - b (v . n)) n,  d = (proxy - x) . n > 0 (else F = 0),
 * for the device's own current position x and velocity v, clamped to
 * max_force. Because the force depends on where the hand is now, a delayed
 * feedback sample moves the plane, not the sign of the work done. A spring
 * sampled at period T with a zero-order hold still generates energy (about
 * k T / 2 per unit squared velocity); the damping b >= k T / 2 removes it
 * (docs/numerics.md §6), and the force never pulls the hand into the wall. */
#ifndef VISCERA_CONTACT_MODEL_H
#define VISCERA_CONTACT_MODEL_H

#include <stdint.h>

typedef struct contact_model {
  int in_contact;
  double proxy[3];
  double normal[3]; /* unit */
  double stiffness; /* N/m */
  double damping;   /* N s/m, set by the client from its period: passivity needs >= k T / 2 */
  uint64_t cmd_seq; /* the ToolCommand the server answered (contact_render.h re-anchors to it) */
} contact_model_t;

/* Writes the force into f and returns its magnitude. v may be NULL (no damping). */
double contact_model_force(const contact_model_t *m, const double x[3], const double v[3], double max_force,
                           double f[3]);

/* The damping that keeps a wall of stiffness k passive at sample period T:
 * k T (twice the k T / 2 minimum, for margin against jitter). */
static inline double contact_model_passive_damping(double k, double period_s) { return k * period_s; }

/* The stiffness to render: the server's contact stiffness k, clamped to
 * the device's stiffness rating k_device (device capability data; 0 = no
 * stated limit). */
static inline double contact_model_device_stiffness(double k, double k_device) {
  return k_device > 0 && k > k_device ? k_device : k;
}

#endif
