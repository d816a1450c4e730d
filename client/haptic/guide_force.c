/* SPDX-License-Identifier: Apache-2.0 */
#include "guide_force.h"

#include <math.h>
#include <string.h>

#include "vmath.h"

int guide_role_valid(const guide_role_t *r) {
  return r && r->known && r->guide[0] && isfinite(r->authority) && r->authority >= 0 && r->authority <= 1 &&
         isfinite(r->coupling_stiffness) && r->coupling_stiffness > 0 &&
         r->coupling_stiffness <= GUIDE_MAX_COUPLING_STIFFNESS;
}

guide_side_t guide_side_of(const guide_role_t *r, const char *own) {
  if (!guide_role_valid(r)) return GUIDE_SIDE_NONE;
  if (!own) own = "";
  /* A station named as both owner and guide has no peer to couple to. */
  if (r->owner[0] && strcmp(r->owner, r->guide) == 0) return GUIDE_SIDE_NONE;
  if (strcmp(own, r->guide) == 0) return GUIDE_SIDE_GUIDE;
  if (r->owner[0] == 0 || strcmp(own, r->owner) == 0) return GUIDE_SIDE_OWNER;
  return GUIDE_SIDE_NONE;
}

int guide_is_peer(const guide_role_t *r, guide_side_t side, const char *station) {
  if (!station) station = "";
  switch (side) {
  case GUIDE_SIDE_OWNER:
    return strcmp(station, r->guide) == 0;
  case GUIDE_SIDE_GUIDE:
    /* An owner "" means any station drives the tool: every station that is
     * not the guide's is the owner side. */
    return r->owner[0] ? strcmp(station, r->owner) == 0 : strcmp(station, r->guide) != 0;
  case GUIDE_SIDE_NONE:
    break;
  }
  return 0;
}

double guide_own_share(const guide_role_t *r, guide_side_t side) {
  switch (side) {
  case GUIDE_SIDE_OWNER:
    return 1.0 - r->authority;
  case GUIDE_SIDE_GUIDE:
    return r->authority;
  case GUIDE_SIDE_NONE:
    break;
  }
  return 1.0;
}

/* Scales f down to max_force when longer; returns the final magnitude. */
static double clamp_force(double f[3], double max_force) {
  double mag = v3_norm(f);
  if (!isfinite(mag)) {
    v3_set(f, 0, 0, 0);
    return 0;
  }
  if (mag > max_force) {
    v3_scale(f, f, max_force / mag);
    mag = max_force;
  }
  return mag;
}

double guide_coupling_damping(double w, double k, double period_s, double rtt_s) {
  double tau = isfinite(rtt_s) && rtt_s > 0 ? rtt_s : 0;
  return (1.0 - w) * k * (period_s + 0.5 * tau);
}

void guide_force(const guide_input_t *in, guide_output_t *out) {
  memset(out, 0, sizeof *out);
  out->side = guide_side_of(in->role, in->own_station);
  out->w = 1.0;
  v3_copy(out->x_tool, in->x);
  int coupled = out->side != GUIDE_SIDE_NONE && in->have_peer && v3_isfinite(in->peer) && isfinite(in->peer_age_s) &&
                in->peer_age_s >= 0 && in->peer_age_s <= GUIDE_PEER_TIMEOUT_S && in->server_silent_s >= 0 &&
                in->server_silent_s <= GUIDE_SERVER_TIMEOUT_S;
  if (!coupled) {
    out->why = !in->role->known                                                   ? "no role"
               : !in->role->guide[0]                                              ? "no guide"
               : out->side == GUIDE_SIDE_NONE                                     ? "not in the role"
               : !in->have_peer || !v3_isfinite(in->peer)                         ? "no peer"
               : !(in->peer_age_s >= 0 && in->peer_age_s <= GUIDE_PEER_TIMEOUT_S) ? "peer silent"
                                                                                  : "server silent";
    /* Plain rendering, exactly as without roles. */
    contact_model_force(in->contact, in->x, in->v, in->max_force, out->f);
    out->magnitude = clamp_force(out->f, in->max_force);
    return;
  }
  double w = guide_own_share(in->role, out->side);
  double k = contact_model_device_stiffness(in->role->coupling_stiffness, in->max_stiffness);
  /* The tool is where the server puts it: w of our hand, 1 - w of the peer's. */
  double x_tool[3], v_tool[3];
  for (int i = 0; i < 3; i++) x_tool[i] = w * in->x[i] + (1.0 - w) * in->peer[i];
  v3_scale(v_tool, in->v, w);
  double fc[3];
  if (in->render)
    contact_render_target(in->render, in->contact, x_tool, v_tool, fc);
  else
    contact_model_force(in->contact, x_tool, v_tool, in->max_force, fc);
  double f[3], b = guide_coupling_damping(w, k, in->period_s, in->rtt_s);
  for (int i = 0; i < 3; i++) f[i] = w * fc[i] + (1.0 - w) * k * (in->peer[i] - in->x[i]) - b * in->v[i];
  v3_copy(out->f, f);
  out->magnitude = clamp_force(out->f, in->max_force);
  out->coupled = 1;
  out->w = w;
  out->k = k;
  v3_copy(out->x_tool, x_tool);
}
