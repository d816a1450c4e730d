/* SPDX-License-Identifier: Apache-2.0 */
#include "recording_data.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "events_by_name.h"
#include "recording/rec_decode.h"
#include "recording/rec_writers.h"
#include "viscera.h"

/* A tool tip that moved less than this has not started moving (m): the
 * scripted and real devices jitter by far less. */
#define FIRST_MOTION_EPS 1e-4

static void warn(rep_recording_t *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void warn(rep_recording_t *r, const char *fmt, ...) {
  size_t len = strlen(r->warnings);
  if (len + 2 >= sizeof r->warnings) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(r->warnings + len, sizeof r->warnings - len, fmt, ap);
  va_end(ap);
  len = strlen(r->warnings);
  if (len + 1 < sizeof r->warnings) r->warnings[len] = '\n', r->warnings[len + 1] = 0;
}

/* Grows *arr (of `size`-byte items) to hold one more; false when out of memory. */
static bool grow(void **arr, size_t *cap, size_t n, size_t size) {
  if (n < *cap) return true;
  size_t nc = *cap ? 2 * *cap : 1024;
  void *na = realloc(*arr, nc * size);
  if (!na) return false;
  *arr = na;
  *cap = nc;
  return true;
}

typedef struct load_ctx {
  rep_recording_t *r;
  bool oom;
  int32_t task_started, task_completed; /* enum values, -1 when this build has none */
  uint64_t last_event_seq[REP_MAX_TOOLS + 1];
  int64_t last_event_writer[REP_MAX_TOOLS + 1];
  bool seen_event_source[REP_MAX_TOOLS + 1];
  /* ContactFeedback writers: a server restarted mid-session follows its
   * predecessor (few switches); servers of several sessions recorded into
   * one file (a partition pattern) interleave (many). */
  int64_t last_fb_writer;
  uint64_t fb_writer_switches;
  /* A restarted server (resumed from its checkpoint, or from rest) goes on
   * from an earlier simulated time than its predecessor reached; what the
   * predecessor did after that time was rolled back with it. Per tool the
   * writer of its last feedback, then what was left out. */
  int64_t tool_fb_writer[REP_MAX_TOOLS];
  /* Writers met so far (a restart is a writer never met before; two
   * servers taking turns, a mixed recording, are not restarts). */
  int64_t met[64];
  size_t nmet;
  uint64_t rolled_back; /* feedback samples left out */
  uint32_t restarts;    /* restarts seen in the feedback */
  double first_restart; /* simulated time the first restart went on from */
  int64_t last_ev_writer;
  double last_ev_t;
  bool ev_seen;
  uint64_t events_rolled_back;
  /* Threshold crossings from the events, (time, level), until counted. */
  struct crossing {
    double t;
    int k;
  } * cross;
  size_t ncross, capcross;
  /* One seat of a lab: only rows of writers in partition `seat` count. */
  const char *seat;
  const rec_writer_t *writers;
  size_t nwriters;
} load_ctx_t;

/* True the first time writer `id` is met (and remembers it while there is room). */
static bool first_met(load_ctx_t *c, int64_t id) {
  for (size_t i = 0; i < c->nmet; i++)
    if (c->met[i] == id) return false;
  if (c->nmet < sizeof c->met / sizeof c->met[0]) c->met[c->nmet++] = id;
  return true;
}

static bool in_seat(const load_ctx_t *c, const recfile_row_t *row) {
  if (!c->seat) return true;
  const rec_writer_t *w = rec_writer_find(c->writers, c->nwriters, row->writer_id);
  return w && strcmp(w->partitions, c->seat) == 0;
}

static rep_tool_t *tool_of(rep_recording_t *r, uint32_t id) {
  if (id >= REP_MAX_TOOLS) return NULL;
  rep_tool_t *t = &r->tools[id];
  if (!t->present) {
    t->present = true;
    snprintf(t->name, sizeof t->name, "tool %u", id);
  }
  if ((int)id + 1 > r->ntools) r->ntools = (int)id + 1;
  return t;
}

static int on_scene(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *c = arg;
  if (!in_seat(c, row)) return 0;
  const viscera_SceneInfo *si = sample;
  rep_recording_t *r = c->r;
  r->have_scene_info = true;
  snprintf(r->scene, sizeof r->scene, "%s", si->scene);
  if (isfinite(si->physics_dt) && si->physics_dt > 0 && si->physics_dt < 1) r->physics_dt = si->physics_dt;
  for (uint32_t i = 0; i < si->tools._length; i++) {
    const viscera_ToolInfo *ti = &si->tools._buffer[i];
    rep_tool_t *t = tool_of(r, ti->tool_id);
    if (!t) continue;
    snprintf(t->name, sizeof t->name, "%s", ti->name);
    const float lv[THR_COUNT] = {ti->st, ti->mpf, ti->sft};
    for (int k = 0; k < THR_COUNT; k++) t->levels[k] = isfinite(lv[k]) && lv[k] > 0 ? lv[k] : 0;
  }
  return 0;
}

static int on_feedback(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *c = arg;
  if (!in_seat(c, row)) return 0;
  if (row->writer_id > 0) {
    if (c->last_fb_writer > 0 && row->writer_id != c->last_fb_writer) c->fb_writer_switches++;
    c->last_fb_writer = row->writer_id;
  }
  const viscera_ContactFeedback *fb = sample;
  rep_tool_t *t = tool_of(c->r, fb->tool_id);
  if (!t) return 0;
  double f = sqrt((double)fb->force[0] * fb->force[0] + (double)fb->force[1] * fb->force[1] +
                  (double)fb->force[2] * fb->force[2]);
  double ts = (double)fb->sim_time_ns * 1e-9;
  int64_t *last_writer = &c->tool_fb_writer[fb->tool_id];
  bool new_writer = row->writer_id > 0 && first_met(c, row->writer_id);
  if (new_writer && t->nforce && *last_writer > 0 && ts < t->force[t->nforce - 1].t) {
    /* Force and proxy samples are appended together: one count for both. */
    size_t keep = t->nforce;
    while (keep && t->force[keep - 1].t >= ts) keep--;
    c->rolled_back += t->nforce - keep;
    t->nforce = t->nproxy = keep;
    if (!c->restarts++) c->first_restart = ts;
  }
  if (row->writer_id > 0) *last_writer = row->writer_id;
  if (!grow((void **)&t->force, &t->capforce, t->nforce, sizeof *t->force) ||
      !grow((void **)&t->proxy, &t->capproxy, t->nproxy, sizeof *t->proxy)) {
    c->oom = true;
    return 1;
  }
  t->force[t->nforce++] = (rep_force_sample_t){ts, isfinite(f) ? f : 0, fb->in_contact ? 1 : 0};
  t->proxy[t->nproxy++] =
      (rep_pos_sample_t){ts, {fb->proxy_position[0], fb->proxy_position[1], fb->proxy_position[2]}, 0};
  return 0;
}

static int on_command(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *c = arg;
  if (!in_seat(c, row)) return 0;
  const viscera_ToolCommand *cmd = sample;
  rep_tool_t *t = tool_of(c->r, cmd->tool_id);
  if (!t) return 0;
  if (!grow((void **)&t->cmd, &t->capcmd, t->ncmd, sizeof *t->cmd)) {
    c->oom = true;
    return 1;
  }
  t->cmd[t->ncmd++] = (rep_pos_sample_t){
      (double)row->source_ts_ns * 1e-9, {cmd->position[0], cmd->position[1], cmd->position[2]}, cmd->seq};
  return 0;
}

/* "ST crossed up: ..." -> THR_ST; -1 when the text names no threshold. */
static int threshold_of_text(const char *text) {
  for (int k = 0; k < THR_COUNT; k++) {
    const char *n = thr_name((thr_id_t)k);
    size_t len = strlen(n);
    if (strncmp(text, n, len) == 0 && (text[len] == ' ' || text[len] == ':' || text[len] == 0)) return k;
  }
  return -1;
}

/* The task an event is about: the id and name the server puts in it; an
 * event without them (another writer) is named by its text, "task 'NAME'
 * ..." as the server words it, else the text's first word. */
static void task_of_event(const viscera_SessionEvent *e, rep_task_event_t *te) {
  te->id = e->task_id >= 0 && e->task_name[0] ? e->task_id : -1;
  if (te->id >= 0) {
    snprintf(te->name, sizeof te->name, "%.63s", e->task_name);
    return;
  }
  const char *b = e->text;
  size_t len = strcspn(b, " :");
  const char *q = strstr(e->text, "task '");
  if (q) {
    b = q + 6;
    const char *end = strchr(b, '\'');
    len = end ? (size_t)(end - b) : strlen(b);
  }
  if (len >= sizeof te->name) len = sizeof te->name - 1;
  memcpy(te->name, b, len);
  te->name[len] = 0;
  if (!te->name[0]) snprintf(te->name, sizeof te->name, "task");
}

/* A cut begins (a new entry) or ends (the tool's open cut, or an entry of
 * its own when its beginning is not in the recording). false: out of
 * memory. */
static bool on_cut(rep_recording_t *r, const viscera_SessionEvent *e, double et, bool begin) {
  rep_cut_t *cut = NULL;
  for (size_t i = r->ncuts; !begin && i-- > 0;)
    if (r->cuts[i].tool == e->tool_id && isnan(r->cuts[i].t_end)) {
      cut = &r->cuts[i];
      break;
    }
  if (!cut) {
    if (!grow((void **)&r->cuts, &r->capcuts, r->ncuts, sizeof *r->cuts)) return false;
    cut = &r->cuts[r->ncuts++];
    *cut = (rep_cut_t){
        .t_begin = begin ? et : NAN, .t_end = NAN, .tool = e->tool_id, .organ = e->organ_id, .changes = NAN};
  }
  if (!begin) {
    cut->t_end = et;
    cut->changes = isfinite(e->value) && e->value >= 0 ? e->value : NAN;
    snprintf(cut->result, sizeof cut->result, "%s", e->text);
  }
  return true;
}

static int on_event(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *c = arg;
  if (!in_seat(c, row)) return 0;
  const viscera_SessionEvent *e = sample;
  rep_recording_t *r = c->r;
  /* A reliable transient-local event can reach the recorder twice (late
   * joiner plus live); count each (writer, source, seq) once. A restarted
   * server is a new writer whose seq starts again. */
  uint32_t src = e->source_id <= REP_MAX_TOOLS ? e->source_id : REP_MAX_TOOLS;
  if (c->seen_event_source[src] && row->writer_id == c->last_event_writer[src] && e->seq <= c->last_event_seq[src])
    return 0;
  c->seen_event_source[src] = true;
  c->last_event_writer[src] = row->writer_id;
  c->last_event_seq[src] = e->seq;
  r->nevents++;
  double et = (double)e->sim_time_ns * 1e-9;
  bool new_writer = row->writer_id > 0 && first_met(c, row->writer_id);
  if (new_writer && c->ev_seen && et < c->last_ev_t) {
    /* A restarted server: its predecessor's events after `et` were rolled back. */
    size_t n = 0;
    for (size_t i = 0; i < c->ncross; i++)
      if (c->cross[i].t < et) c->cross[n++] = c->cross[i];
    c->events_rolled_back += c->ncross - n;
    c->ncross = n;
    n = 0;
    for (size_t i = 0; i < r->ntask_events; i++)
      if (r->task_events[i].t < et) r->task_events[n++] = r->task_events[i];
    c->events_rolled_back += r->ntask_events - n;
    r->ntask_events = n;
    n = 0;
    for (size_t i = 0; i < r->ncuts; i++)
      if (!(r->cuts[i].t_begin >= et)) r->cuts[n++] = r->cuts[i];
    c->events_rolled_back += r->ncuts - n;
    r->ncuts = n;
    for (size_t i = 0; i < r->ncuts; i++)
      if (r->cuts[i].t_end >= et) r->cuts[i].t_end = r->cuts[i].changes = NAN, r->cuts[i].result[0] = 0;
  }
  c->ev_seen = true;
  c->last_ev_writer = row->writer_id;
  c->last_ev_t = et;
  int32_t kind = (int32_t)e->kind;
  if (kind == (int32_t)viscera_EVENT_THRESHOLD_CROSSED_UP) {
    int k = threshold_of_text(e->text);
    if (k >= 0) {
      if (!grow((void **)&c->cross, &c->capcross, c->ncross, sizeof *c->cross)) {
        c->oom = true;
        return 1;
      }
      c->cross[c->ncross++] = (struct crossing){et, k};
    }
  } else if (kind >= 0 && (kind == c->task_started || kind == c->task_completed)) {
    if (!grow((void **)&r->task_events, &r->captask_events, r->ntask_events, sizeof *r->task_events)) {
      c->oom = true;
      return 1;
    }
    rep_task_event_t *te = &r->task_events[r->ntask_events++];
    te->t = (double)e->sim_time_ns * 1e-9;
    te->mark = kind == c->task_started ? REP_TASK_STARTED : REP_TASK_COMPLETED;
    te->value = te->mark == REP_TASK_COMPLETED && isfinite(e->value) ? e->value : NAN;
    task_of_event(e, te);
  } else if (kind == (int32_t)viscera_EVENT_CUT_BEGIN || kind == (int32_t)viscera_EVENT_CUT_END) {
    if (!on_cut(r, e, et, kind == (int32_t)viscera_EVENT_CUT_BEGIN)) {
      c->oom = true;
      return 1;
    }
  }
  /* Other kinds (grasps, instructor commands, topology changes) are the
   * session's record, not measures: nothing is lost by leaving them. */
  return 0;
}

static int on_metrics(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *c = arg;
  if (!in_seat(c, row)) return 0;
  const viscera_Metrics *m = sample;
  rep_recording_t *r = c->r;
  r->have_metrics = true;
  r->metrics_time_above[THR_ST] = m->time_above_st;
  r->metrics_time_above[THR_MPF] = m->time_above_mpf;
  r->metrics_time_above[THR_SFT] = m->time_above_sft;
  r->metrics_contact_time = m->contact_time;
  r->metrics_mean_force = m->mean_contact_force;
  r->metrics_peak = m->peak_force;
  r->metrics_path = m->path_length;
  return 0;
}

/* Reads one topic and turns what went wrong into warnings; returns the
 * samples that did not decode (warned about unless `quiet_undecodable`). */
static uint64_t load_topic(rep_recording_t *r, recfile_t *rf, const char *topic, const dds_topic_descriptor_t *desc,
                           rec_decode_cb cb, load_ctx_t *c, bool needed, bool quiet_undecodable) {
  rec_decode_report_t rep;
  if (rec_decode_topic(rf, topic, desc, cb, c, &rep) < 0) c->oom = true;
  const char *shortname = strncmp(topic, "viscera_", 8) == 0 ? topic + 8 : topic;
  if (rep.topic_missing) {
    if (needed) warn(r, "no %s topic in the recording", shortname);
    return 0;
  }
  if (rep.scan.damaged || rep.scan.invalid) {
    r->damaged = true;
    warn(r, "%s: %u damaged region(s), %llu unreadable row(s)%s (first: %s); %llu samples read", shortname,
         rep.scan.damaged, (unsigned long long)rep.scan.invalid, rep.scan.gave_up ? ", gave up on the rest" : "",
         rep.scan.first_error[0] ? rep.scan.first_error : "invalid rows", (unsigned long long)rep.decoded);
  }
  if (rep.undecodable && !quiet_undecodable)
    warn(r, "%s: %llu sample(s) do not decode (damaged, or written with a newer type) and were skipped", shortname,
         (unsigned long long)rep.undecodable);
  return rep.undecodable;
}

static void summarise(rep_recording_t *r) {
  rep_summary_t *s = &r->sum;
  memset(s, 0, sizeof *s);
  double force_integral = 0, first_motion = INFINITY, first_contact = INFINITY, last_end = -INFINITY;
  double t0 = INFINITY, t1 = -INFINITY;
  bool levels_set = false;
  for (int i = 0; i < r->ntools; i++) {
    rep_tool_t *t = &r->tools[i];
    if (!t->present) continue;
    rep_force_measures(t->force, t->nforce, t->levels, r->physics_dt, REP_GAP_S, &t->fm);
    t->path_length = rep_path_length(t->cmd, t->ncmd, REP_GAP_S);
    s->peak_force = fmax(s->peak_force, t->fm.peak_force);
    s->contact_time += t->fm.contact_time;
    force_integral += t->fm.mean_contact_force * t->fm.contact_time;
    for (int k = 0; k < THR_COUNT; k++) {
      s->time_above[k] += t->fm.time_above[k];
      s->crossings[k] += t->fm.crossings[k];
    }
    s->path_length += t->path_length;
    double fm = rep_first_motion(t->proxy, t->nproxy, FIRST_MOTION_EPS);
    if (isfinite(fm)) first_motion = fmin(first_motion, fm);
    if (isfinite(t->fm.first_contact_t)) first_contact = fmin(first_contact, t->fm.first_contact_t);
    if (isfinite(t->fm.last_contact_end_t)) last_end = fmax(last_end, t->fm.last_contact_end_t);
    if (t->nforce) {
      t0 = fmin(t0, t->fm.first_t);
      t1 = fmax(t1, t->fm.last_t);
    }
    if (!levels_set && (t->levels[0] > 0 || t->levels[1] > 0 || t->levels[2] > 0)) {
      memcpy(s->levels, t->levels, sizeof s->levels);
      levels_set = true;
    }
  }
  s->mean_contact_force = s->contact_time > 0 ? force_integral / s->contact_time : 0;
  /* The server's events are the record of what the trainee was told; the
   * replayed count stands in only when the recording has none. */
  if (r->nevents > 0) {
    s->crossings_from_events = true;
    for (int k = 0; k < THR_COUNT; k++) s->crossings[k] = r->event_crossings[k];
  }
  s->duration = t1 > t0 ? t1 - t0 : 0;
  /* Without motion data the feedback's first sample is the start. */
  if (!isfinite(first_motion)) first_motion = t0;
  s->time_to_first_contact = isfinite(first_contact) && isfinite(first_motion) ? first_contact - first_motion : NAN;
  s->operation_time = isfinite(last_end) && isfinite(first_motion) ? last_end - first_motion : NAN;
  r->ntasks =
      rep_tasks(r->task_events, r->ntask_events, isfinite(first_motion) ? first_motion : 0, r->tasks, REP_MAX_TASKS);
}

/* Who trained in this section: its seat (partition) and, per ToolCommand
 * writer (the trainee's hands), the station and process its participant
 * announced (a claim, vdds_ident.h) and, under DDS Security, its
 * certificate subject as the recorder verified it (vdds_subject.h). */
static void describe_identity(rep_recording_t *r, recfile_t *rf, const load_ctx_t *c) {
  size_t len = (size_t)snprintf(r->identity, sizeof r->identity, "seat %s",
                                c->seat ? c->seat : (r->session.partition[0] ? r->session.partition : "?"));
  const recfile_topic_t *cmd = recfile_topic_by_name(rf, "viscera_ToolCommand");
  int shown = 0;
  for (size_t i = 0; cmd && i < c->nwriters && len + 256 < sizeof r->identity; i++) {
    const rec_writer_t *w = &c->writers[i];
    if (w->topic_id != cmd->id || (c->seat && strcmp(w->partitions, c->seat) != 0)) continue;
    char station[40] = "", host[64] = "?", pid[16] = "?";
    if (!rec_ident_field(w->participant, "station", station, sizeof station) || !station[0])
      snprintf(station, sizeof station, "anonymous");
    rec_ident_field(w->participant, "host", host, sizeof host);
    rec_ident_field(w->participant, "pid", pid, sizeof pid);
    /* no commas: the CSV's readers split naively (the subject's commas
     * become '/', its RFC 2253 separators) */
    char subject[160];
    snprintf(subject, sizeof subject, "%s", w->subject[0] ? w->subject : "none: not secure");
    for (char *q = subject; *q; q++)
      if (*q == ',') *q = '/';
    len +=
        (size_t)snprintf(r->identity + len, sizeof r->identity - len, "; station %s (%s on %s pid %s; certificate %s)",
                         station, w->role[0] ? w->role : "client", host, pid, subject);
    shown++;
  }
  if (!shown && len + 40 < sizeof r->identity)
    snprintf(r->identity + len, sizeof r->identity - len, "; no trainee client recorded");
}

int rep_recording_seats(const char *path, char (*seats)[128], int max, verr_t *err) {
  recfile_t *rf = NULL;
  if (recfile_open(&rf, path, err) < 0) return -1;
  rec_writer_t *w = NULL;
  size_t nw = 0;
  int n = 0;
  const recfile_topic_t *fb = recfile_topic_by_name(rf, "viscera_ContactFeedback");
  if (fb && rec_writers_load(rf, &w, &nw, err) == 0) {
    for (size_t i = 0; i < nw; i++) {
      if (w[i].topic_id != fb->id || !w[i].partitions[0] || strchr(w[i].partitions, ',')) continue;
      int k = 0;
      while (k < n && strcmp(seats[k], w[i].partitions) < 0) k++;
      if (k < n && strcmp(seats[k], w[i].partitions) == 0) continue;
      if (n == max) break;
      memmove(seats[k + 1], seats[k], (size_t)(n - k) * sizeof seats[0]);
      snprintf(seats[k], sizeof seats[0], "%.127s", w[i].partitions);
      n++;
    }
  }
  free(w);
  recfile_close(rf);
  return n;
}

int rep_recording_load(rep_recording_t *r, const char *path, const char *label, const char *seat, verr_t *err) {
  memset(r, 0, sizeof *r);
  snprintf(r->path, sizeof r->path, "%s", path);
  snprintf(r->label, sizeof r->label, "%s", label);
  if (seat) snprintf(r->seat, sizeof r->seat, "%s", seat);
  r->physics_dt = 1e-3;
  recfile_t *rf = NULL;
  if (recfile_open(&rf, path, err) < 0) return -1;
  rec_writer_t *writers = NULL;
  size_t nwriters = 0;
  verr_t werr = {{0}};
  if (rec_writers_load(rf, &writers, &nwriters, &werr) < 0) {
    warn(r, "%s", werr.msg);
    if (seat) {
      free(writers);
      recfile_close(rf);
      return verr_set(err, "%s: cannot tell the seats apart: %s", path, werr.msg);
    }
  }
  r->session = *recfile_session(rf);
  r->damaged = recfile_damaged(rf);
  const char *w = recfile_warnings(rf);
  if (w[0]) warn(r, "%s", w);
  if (!r->session.valid)
    warn(r, "%s", "session metadata unreadable");
  else if (!r->session.has_end)
    warn(r, "%s", "the recording has no end time (recorder killed or still running): it may stop early");

  load_ctx_t c = {
      .r = r, .task_started = -1, .task_completed = -1, .seat = seat, .writers = writers, .nwriters = nwriters};
  /* Task events are newer than this tool's code: found by name in the
   * compiled type, so they work as soon as the IDL has them. */
  rec_decode_enum_value(&viscera_SessionEvent_desc, "EVENT_TASK_STARTED", &c.task_started);
  rec_decode_enum_value(&viscera_SessionEvent_desc, "EVENT_TASK_COMPLETED", &c.task_completed);
  load_topic(r, rf, "viscera_SceneInfo", &viscera_SceneInfo_desc, on_scene, &c, true, false);
  load_topic(r, rf, "viscera_ContactFeedback", &viscera_ContactFeedback_desc, on_feedback, &c, true, false);
  load_topic(r, rf, "viscera_ToolCommand", &viscera_ToolCommand_desc, on_command, &c, true, false);
  if (load_topic(r, rf, "viscera_SessionEvent", &viscera_SessionEvent_desc, on_event, &c, true, true)) {
    /* Events of an older (or newer) SessionEvent type: by field name. */
    uint64_t left = 0, salvaged = rep_events_by_name(rf, on_event, &c, &left);
    if (salvaged)
      warn(r, "SessionEvent: %llu event(s) of another version of the type were read by field name",
           (unsigned long long)salvaged);
    if (left)
      warn(r, "SessionEvent: %llu sample(s) do not decode (damaged?) and were skipped", (unsigned long long)left);
  }
  load_topic(r, rf, "viscera_Metrics", &viscera_Metrics_desc, on_metrics, &c, false, false);
  describe_identity(r, rf, &c);
  free(writers);
  recfile_close(rf);
  for (size_t i = 0; i < c.ncross; i++) r->event_crossings[c.cross[i].k]++;
  free(c.cross);
  if (c.oom) return verr_set(err, "%s: out of memory while reading", path);
  if (c.restarts)
    warn(r,
         "the server restarted %u time(s) (resumed from its checkpoint, or from rest), first going on from "
         "simulated time %.3f s: %llu force sample(s) and %llu event(s) of the run before, later than where the "
         "next run went on, are left out, as the restarted server's own measures leave them",
         c.restarts, c.first_restart, (unsigned long long)c.rolled_back, (unsigned long long)c.events_rolled_back);
  if (!r->have_scene_info) warn(r, "%s", "no SceneInfo: thresholds unknown (ST/MPF/SFT measures are 0)");
  if (c.fb_writer_switches > 10)
    warn(r,
         "ContactFeedback from several servers interleaves (%llu switches): the recording holds several sessions "
         "(recorded with a partition pattern?) and the figures mix them; record one partition per file",
         (unsigned long long)c.fb_writer_switches);
  size_t nforce = 0, ncmd = 0;
  for (int i = 0; i < r->ntools; i++) nforce += r->tools[i].nforce, ncmd += r->tools[i].ncmd;
  if (!nforce && !ncmd)
    return verr_set(err, "%s: no readable ContactFeedback or ToolCommand sample: nothing to report%s", path,
                    r->damaged ? " (the file is damaged)" : "");
  if (!nforce) warn(r, "%s", "no ContactFeedback samples: force measures are empty");
  summarise(r);
  return 0;
}

void rep_recording_free(rep_recording_t *r) {
  for (int i = 0; i < REP_MAX_TOOLS; i++) {
    free(r->tools[i].force);
    free(r->tools[i].cmd);
    free(r->tools[i].proxy);
  }
  free(r->task_events);
  free(r->cuts);
  memset(r, 0, sizeof *r);
}
