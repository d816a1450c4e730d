/* contact_model: the local force model the haptic client renders at 1 kHz
 * from the latest ContactFeedback: a plane through the proxy with outward
 * normal n and stiffness k. F = k * max(0, (proxy - x) . n) * n for the
 * device's own current position x, clamped to max_force. Because the force
 * depends only on where the hand is now, a delayed feedback sample changes
 * the plane, not the sign of the work done: the wall stays passive. */
#ifndef VISCERA_CONTACT_MODEL_H
#define VISCERA_CONTACT_MODEL_H

typedef struct contact_model {
  int in_contact;
  double proxy[3];
  double normal[3]; /* unit */
  double stiffness; /* N/m */
} contact_model_t;

/* Writes the force into f and returns its magnitude. */
double contact_model_force(const contact_model_t *m, const double x[3], double max_force, double f[3]);

#endif
