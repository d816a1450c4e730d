/* SPDX-License-Identifier: Apache-2.0 */
#include "guide_report.h"

#include <stdlib.h>
#include <string.h>

#include "vstats.h"

static const char *side_name(guide_side_t s) {
  return s == GUIDE_SIDE_OWNER ? "owner (trainee)" : s == GUIDE_SIDE_GUIDE ? "guide (instructor)" : "none";
}

int guide_report_init(guide_report_t *r, size_t age_capacity) {
  memset(r, 0, sizeof *r);
  r->w = 1; /* as plain rendering reports it: no line until something changes */
  if (age_capacity) {
    r->peer_age_us = malloc(age_capacity * sizeof *r->peer_age_us);
    if (!r->peer_age_us) return -1;
    r->cap_age = age_capacity;
  }
  return 0;
}

void guide_report_free(guide_report_t *r) {
  free(r->peer_age_us);
  r->peer_age_us = NULL;
  r->cap_age = r->n_age = 0;
}

void guide_report_tick(guide_report_t *r, double t, const guide_role_t *role, const char *peer, double peer_age_s,
                       const guide_output_t *o, FILE *log) {
  if (!peer || !o->coupled) peer = "";
  if (o->coupled) {
    if (o->side == GUIDE_SIDE_OWNER) r->ticks_owner++;
    if (o->side == GUIDE_SIDE_GUIDE) r->ticks_guide++;
    r->last_side = o->side;
    r->last_authority = role->authority;
    r->last_k = o->k;
    snprintf(r->last_peer, sizeof r->last_peer, "%s", peer);
    if (r->n_age < r->cap_age) r->peer_age_us[r->n_age++] = peer_age_s * 1e6;
  }
  /* A new role version is worth a line even when the coupling it gives is
   * the same (e.g. an assignment to us while unguided). */
  int role_changed = role->known != r->role_known || (role->known && role->version != r->role_version);
  /* Why we are not coupled, once a role is known (before that there is
   * nothing to say: a server without roles, or one still starting). */
  const char *why = o->why ? o->why : "", *was = r->why ? r->why : "";
  int changed = o->coupled != r->coupled || o->side != r->side || o->w != r->w || o->k != r->k ||
                strcmp(peer, r->peer) != 0 || (!o->coupled && role->known && strcmp(why, was) != 0);
  if (!changed && !role_changed) return;
  r->coupled = o->coupled;
  r->side = o->side;
  r->w = o->w;
  r->k = o->k;
  snprintf(r->peer, sizeof r->peer, "%s", peer);
  r->role_known = role->known;
  r->role_version = role->version;
  r->why = o->why;
  r->changes++;
  if (!log) return;
  if (o->coupled)
    fprintf(log, "haptic: t=%.3f s guide: coupled as %s, own share %.2f, k %.0f N/m, peer %s (role v%u)\n", t,
            side_name(o->side), o->w, o->k, peer[0] ? peer : "(anonymous)", role->version);
  else
    fprintf(log, "haptic: t=%.3f s guide: not coupled (%s; role v%u: owner '%s', guide '%s')\n", t,
            o->why ? o->why : "?", role->version, role->owner, role->guide);
}

double guide_report_coupled_s(const guide_report_t *r, double period_s) {
  return (double)(r->ticks_owner + r->ticks_guide) * period_s;
}

void guide_report_summary(const guide_report_t *r, double period_s, FILE *f) {
  if (!r->ticks_owner && !r->ticks_guide) {
    fprintf(f, "haptic: GUIDE never coupled\n");
    return;
  }
  fprintf(f,
          "haptic: GUIDE coupled %.1f s as owner (trainee), %.1f s as guide (instructor); last: as %s, authority "
          "%.2f, k %.0f N/m, peer %s\n",
          (double)r->ticks_owner * period_s, (double)r->ticks_guide * period_s, side_name(r->last_side),
          r->last_authority, r->last_k, r->last_peer[0] ? r->last_peer : "(anonymous)");
  if (r->n_age) {
    vstats_summary_t a = vstats_summarise(r->peer_age_us, r->n_age);
    fprintf(f,
            "haptic: GUIDE peer position age when rendered (since its arrival): median %.0f us, p99 %.0f us, max %.0f "
            "us (%zu ticks)\n",
            a.median, a.p99, a.max, a.n);
  }
}
