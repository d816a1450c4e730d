/* SPDX-License-Identifier: Apache-2.0 */
#include "training/measures.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

void rep_force_measures(const rep_force_sample_t *s, size_t n, const double levels[THR_COUNT], double dt_nominal,
                        double gap_s, rep_force_measures_t *m) {
  memset(m, 0, sizeof *m);
  m->first_contact_t = NAN;
  m->last_contact_end_t = NAN;
  m->samples = n;
  if (!n) return;
  thr_tracker_t tr;
  thr_init(&tr, levels[THR_ST], levels[THR_MPF], levels[THR_SFT]);
  int was_contact = 0;
  for (size_t i = 0; i < n; i++) {
    double dt = i > 0 ? s[i].t - s[i - 1].t : dt_nominal;
    /* Two samples of one simulated instant (the server answers a command
     * before the tissue step, stamped with the step's start, right after
     * the previous step's own answer, stamped with its end) take no time. */
    if (dt != 0 && (!(dt > 0) || (dt > gap_s && !(s[i].in_contact && s[i - 1].in_contact)))) dt = dt_nominal;
    thr_event_t ev[THR_COUNT];
    thr_update(&tr, dt, s[i].force, s[i].in_contact, NULL, ev);
    if (s[i].in_contact && isnan(m->first_contact_t)) m->first_contact_t = s[i].t;
    if (was_contact && !s[i].in_contact) m->last_contact_end_t = s[i].t;
    was_contact = s[i].in_contact;
  }
  /* Still in contact when the recording ends: the contact ends there. */
  if (was_contact) m->last_contact_end_t = s[n - 1].t;
  m->peak_force = tr.peak_force;
  m->mean_contact_force = thr_mean_contact_force(&tr);
  m->contact_time = tr.contact_time;
  for (int k = 0; k < THR_COUNT; k++) {
    m->time_above[k] = tr.time_above[k];
    m->crossings[k] = tr.crossings[k];
  }
  m->first_t = s[0].t;
  m->last_t = s[n - 1].t;
}

static int finite3(const double p[3]) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }

double rep_path_length(const rep_pos_sample_t *p, size_t n, double gap_s) {
  double len = 0;
  const rep_pos_sample_t *prev = NULL;
  for (size_t i = 0; i < n; i++) {
    if (!finite3(p[i].p)) {
      prev = NULL;
      continue;
    }
    if (prev) {
      double dt = p[i].t - prev->t;
      bool lost_between = prev->seq && p[i].seq > prev->seq + 1;
      if (dt >= 0 && (dt <= gap_s || lost_between)) {
        double dx = p[i].p[0] - prev->p[0], dy = p[i].p[1] - prev->p[1], dz = p[i].p[2] - prev->p[2];
        len += sqrt(dx * dx + dy * dy + dz * dz);
      }
    }
    prev = &p[i];
  }
  return len;
}

double rep_first_motion(const rep_pos_sample_t *p, size_t n, double eps) {
  const rep_pos_sample_t *first = NULL;
  for (size_t i = 0; i < n; i++) {
    if (!finite3(p[i].p)) continue;
    if (!first) {
      first = &p[i];
      continue;
    }
    double dx = p[i].p[0] - first->p[0], dy = p[i].p[1] - first->p[1], dz = p[i].p[2] - first->p[2];
    if (dx * dx + dy * dy + dz * dz > eps * eps) return p[i].t;
  }
  return NAN;
}

/* Two tasks may share a name (a scene names them freely), never an id. */
static bool same_task(const rep_task_t *t, const rep_task_event_t *e) {
  if (t->id >= 0 && e->id >= 0) return t->id == e->id;
  return strcmp(t->name, e->name) == 0;
}

size_t rep_tasks(const rep_task_event_t *ev, size_t n, double session_start, rep_task_t *out, size_t cap) {
  size_t nt = 0;
  for (size_t i = 0; i < n; i++) {
    rep_task_t *t = NULL;
    /* the latest task of that name: a name can repeat (task done twice) */
    for (size_t k = nt; k-- > 0;)
      if (same_task(&out[k], &ev[i])) {
        t = &out[k];
        break;
      }
    if (ev[i].mark == REP_TASK_STARTED) {
      if (t && isnan(t->end)) { /* restarted before completion */
        t->start = ev[i].t;
        continue;
      }
      if (nt >= cap) break;
      t = &out[nt++];
      memset(t, 0, sizeof *t);
      snprintf(t->name, sizeof t->name, "%s", ev[i].name);
      t->id = ev[i].id;
      t->start = ev[i].t;
      t->end = NAN;
      t->started_seen = 1;
    } else {
      if (t && isnan(t->end)) {
        t->end = ev[i].t;
        if (isfinite(ev[i].value) && ev[i].value >= 0) t->start = t->end - ev[i].value;
        continue;
      }
      if (nt >= cap) break;
      t = &out[nt++];
      memset(t, 0, sizeof *t);
      snprintf(t->name, sizeof t->name, "%s", ev[i].name);
      t->id = ev[i].id;
      t->start = session_start;
      t->end = ev[i].t;
      t->started_seen = 0;
    }
  }
  return nt;
}
