/* SPDX-License-Identifier: Apache-2.0 */
#include "session/tool_roles.h"

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "station.h"
#include "dds/vdds.h"

_Static_assert(TOOL_ROLE_STATION_MAX == VDDS_STATION_MAX, "one station name size");

static void copy_station(char dst[TOOL_ROLE_STATION_MAX], const char *src) {
  snprintf(dst, TOOL_ROLE_STATION_MAX, "%s", src ? src : "");
}

void tool_roles_init(tool_roles_t *r, const scene_t *scene) {
  memset(r, 0, sizeof *r);
  r->ntools = scene->ntools;
  for (size_t t = 0; t < r->ntools; t++) {
    tool_role_t *tr = &r->tool[t];
    snprintf(tr->name, sizeof tr->name, "%s", scene->tools[t].name);
    copy_station(tr->owner, scene->tools[t].station);
    tr->max_coupling = scene->tools[t].stiffness;
    tr->version = 1;
  }
  r->playout_depth = PLAYOUT_DEFAULT_DEPTH;
  r->changed = r->ntools ? (uint32_t)((1ull << r->ntools) - 1) : 0;
}

tool_side_t tool_roles_classify(const tool_roles_t *r, size_t t, const char *station) {
  const tool_role_t *tr = &r->tool[t];
  if (!station) station = "";
  /* The guide first: with owner "" (anyone) the guide's commands must
   * still be coupled in, not taken as the owner's. */
  if (tr->guide[0] && !strcmp(station, tr->guide)) return TOOL_SIDE_GUIDE;
  if (!tr->owner[0] || !strcmp(station, tr->owner)) return TOOL_SIDE_OWNER;
  return TOOL_SIDE_REJECTED;
}

void tool_roles_note(tool_roles_t *r, size_t t, tool_side_t side, const char *station, uint64_t writer,
                     const tool_cmd_t *c, uint64_t now_ns) {
  if (t >= r->ntools || side == TOOL_SIDE_REJECTED) return;
  tool_pose_t *p = &r->tool[t].side[side];
  if (p->writer != writer) command_playout_clear(&p->playout);
  copy_station(p->station, station);
  p->writer = writer;
  tool_input_t in;
  tool_input_from_cmd(c, &in);
  command_playout_push(&p->playout, r->playout_depth, &in);
  p->mono_ns = now_ns;
}

int tool_roles_stale(const tool_roles_t *r, size_t t, tool_side_t side, uint64_t writer, uint64_t seq) {
  if (t >= r->ntools || side == TOOL_SIDE_REJECTED) return 0;
  const tool_pose_t *p = &r->tool[t].side[side];
  if (p->writer != writer) return 0;
  if (p->playout.n) return seq <= p->playout.wait[p->playout.n - 1].seq;
  return p->has && seq <= p->cmd.seq;
}

uint32_t tool_roles_advance(tool_roles_t *r) {
  uint32_t moved = 0;
  for (size_t t = 0; t < r->ntools; t++)
    for (int s = 0; s < 2; s++) {
      tool_pose_t *p = &r->tool[t].side[s];
      if (command_playout_next(&p->playout, &p->cmd)) {
        p->has = 1;
        moved |= 1u << t;
      }
    }
  return moved;
}

void tool_roles_playout_totals(const tool_roles_t *r, uint64_t *delayed, uint64_t *superseded, uint64_t *caught_up) {
  *delayed = r->delayed;
  *superseded = r->superseded;
  *caught_up = r->caught_up;
  for (size_t t = 0; t < r->ntools; t++)
    for (int s = 0; s < 2; s++) {
      const command_playout_t *q = &r->tool[t].side[s].playout;
      *delayed += q->delayed;
      *superseded += q->superseded;
      *caught_up += q->caught_up;
    }
}

/* Drops a side's commands, in effect and waiting; its counters go to the totals. */
static void forget_side(tool_roles_t *r, tool_pose_t *p) {
  r->delayed += p->playout.delayed;
  r->superseded += p->playout.superseded;
  r->caught_up += p->playout.caught_up;
  memset(p, 0, sizeof *p);
}

static int present(const tool_pose_t *p, uint64_t now_ns) {
  /* A command stamped after now (taken later in the same step) is fresh. */
  return p->has && (now_ns <= p->mono_ns || now_ns - p->mono_ns <= TOOL_ROLE_ABSENT_NS);
}

int tool_roles_effective(const tool_roles_t *r, size_t t, uint64_t now_ns, tool_effective_t *out) {
  memset(out, 0, sizeof *out);
  if (t >= r->ntools) return 0;
  const tool_role_t *tr = &r->tool[t];
  const tool_pose_t *o = &tr->side[TOOL_SIDE_OWNER], *g = &tr->side[TOOL_SIDE_GUIDE];
  out->owner_present = present(o, now_ns);
  out->guide_present = tr->guide[0] && present(g, now_ns);
  if (!out->owner_present && !out->guide_present) return 0;
  if (!out->guide_present) {
    out->cmd = o->cmd;
    return 1;
  }
  if (!out->owner_present) {
    out->cmd = g->cmd;
    return 1;
  }
  double a = tr->authority;
  /* The dominant side gives what cannot be averaged (buttons, the shaft's
   * orientation: a mean of two quaternions is not the pose of either). */
  out->cmd = a >= 0.5 ? g->cmd : o->cmd;
  for (int k = 0; k < 3; k++) out->cmd.pos[k] = a * g->cmd.pos[k] + (1 - a) * o->cmd.pos[k];
  out->cmd.max_force = fmin(o->cmd.max_force, g->cmd.max_force);
  /* The trainee's client measures its latency from this echo. */
  out->cmd.seq = o->cmd.seq;
  out->cmd.echo = o->cmd.echo;
  return 1;
}

int tool_roles_side_of_writer(const tool_roles_t *r, size_t t, uint64_t writer) {
  if (t >= r->ntools) return -1;
  for (int s = 0; s < 2; s++) {
    const tool_pose_t *p = &r->tool[t].side[s];
    if ((p->has || p->playout.n) && p->writer == writer) return s;
  }
  return -1;
}

void tool_roles_forget(tool_roles_t *r, size_t t, tool_side_t side) {
  if (t < r->ntools && side != TOOL_SIDE_REJECTED) forget_side(r, &r->tool[t].side[side]);
}

void tool_roles_forget_all(tool_roles_t *r) {
  for (size_t t = 0; t < r->ntools; t++)
    for (int s = 0; s < 2; s++) forget_side(r, &r->tool[t].side[s]);
  r->changed = r->ntools ? (uint32_t)((1ull << r->ntools) - 1) : 0;
}

const char *tool_roles_who(const char *station, char *buf, size_t n) {
  if (!station || !station[0])
    snprintf(buf, n, "any station");
  else
    snprintf(buf, n, "station '%s'", station);
  return buf;
}

/* After a role change, a side's latest command stays only if its station
 * still drives that side: the tool must not keep following a station that
 * just lost it for the next 100 ms. */
static void revalidate(tool_roles_t *r, size_t t) {
  for (int s = 0; s < 2; s++) {
    tool_pose_t *p = &r->tool[t].side[s];
    if ((p->has || p->playout.n) && tool_roles_classify(r, t, p->station) != (tool_side_t)s) forget_side(r, p);
  }
}

/* Installs the new role; bumps the version only when something changed. */
static int set_role(tool_roles_t *r, size_t t, const char *owner, const char *guide, double a, double k) {
  tool_role_t *tr = &r->tool[t];
  int same = !strcmp(tr->owner, owner) && !strcmp(tr->guide, guide) && tr->authority == a && tr->coupling == k;
  if (same) return 0;
  char o[TOOL_ROLE_STATION_MAX], g[TOOL_ROLE_STATION_MAX];
  copy_station(o, owner); /* owner/guide may point into tr itself */
  copy_station(g, guide);
  memcpy(tr->owner, o, sizeof o);
  memcpy(tr->guide, g, sizeof g);
  tr->authority = a;
  tr->coupling = k;
  tr->version++;
  r->changed |= 1u << t;
  revalidate(r, t);
  return 1;
}

static int refuse(char *text, size_t n, const char *fmt, const char *arg) {
  snprintf(text, n, fmt, arg);
  return -1;
}

static int apply_assign(tool_roles_t *r, size_t t, const char *station, char *text, size_t n) {
  tool_role_t *tr = &r->tool[t];
  int any = !station[0] || !strcmp(station, "*");
  if (!any && !station_name_valid(station))
    return refuse(text, n, "station name '%.40s' is not 1..31 characters of A-Z a-z 0-9 _ . - (or \"*\": any station)",
                  station);
  char was_guide[TOOL_ROLE_STATION_MAX], who[64];
  copy_station(was_guide, tr->guide);
  int changed = set_role(r, t, any ? "" : station, "", 0, 0);
  int k = snprintf(text, n, "tool %zu '%s' assigned to %s", t, tr->name, tool_roles_who(tr->owner, who, sizeof who));
  if (k > 0 && (size_t)k < n) {
    if (was_guide[0])
      snprintf(text + k, n - (size_t)k, "; guiding by station '%s' ended", was_guide);
    else if (!changed)
      snprintf(text + k, n - (size_t)k, " (unchanged)");
  }
  return 0;
}

static int apply_guide(tool_roles_t *r, size_t t, const viscera_SessionControl *c, char *text, size_t n) {
  tool_role_t *tr = &r->tool[t];
  const char *station = c->text;
  char who[64];
  if (!station[0]) { /* guiding ends: the tool is the owner's alone */
    if (!tr->guide[0]) {
      snprintf(text, n, "tool %zu '%s' was not guided (unchanged; driven by %s)", t, tr->name,
               tool_roles_who(tr->owner, who, sizeof who));
      return 0;
    }
    char was[TOOL_ROLE_STATION_MAX];
    copy_station(was, tr->guide);
    set_role(r, t, tr->owner, "", 0, 0);
    snprintf(text, n, "tool %zu '%s': guiding by station '%s' ended, back with %s", t, tr->name, was,
             tool_roles_who(tr->owner, who, sizeof who));
    return 0;
  }
  if (!strcmp(station, "*")) return refuse(text, n, "a guide is one named station, not '%s'", station);
  if (!station_name_valid(station))
    return refuse(text, n, "station name '%.40s' is not 1..31 characters of A-Z a-z 0-9 _ . -", station);
  if (tr->owner[0] && !strcmp(station, tr->owner))
    return refuse(text, n, "station '%s' owns the tool: it cannot also guide it", station);
  double a = c->values[0], k = c->values[1];
  if (!isfinite(a) || a < 0 || a > 1) {
    snprintf(text, n, "authority %g is not a number in 0..1", a);
    return -1;
  }
  if (!isfinite(k)) return refuse(text, n, "coupling stiffness is not finite%s", "");
  if (k <= 0) k = fmin(TOOL_ROLE_DEFAULT_COUPLING, tr->max_coupling);
  if (k > tr->max_coupling) {
    /* A stiffer coupling than the tool's own proxy spring could make the
     * devices push each other harder than tissue ever pushes them. */
    snprintf(text, n, "coupling stiffness %g N/m above the tool's stiffness %g N/m", k, tr->max_coupling);
    return -1;
  }
  int changed = set_role(r, t, tr->owner, station, a, k);
  snprintf(text, n, "tool %zu '%s' %s by station '%s' (authority %.3g, coupling %.4g N/m; owner: %s)%s", t, tr->name,
           a >= 1 ? "taken over" : "guided", station, a, k, tool_roles_who(tr->owner, who, sizeof who),
           changed ? "" : " (unchanged)");
  return 0;
}

int tool_roles_apply(tool_roles_t *r, const viscera_SessionControl *c, char *text, size_t n) {
  if (c->kind != viscera_CONTROL_ASSIGN_TOOL && c->kind != viscera_CONTROL_GUIDE)
    return refuse(text, n, "not a tool role command%s", "");
  if (c->tool_id < 0 || (size_t)c->tool_id >= r->ntools) return refuse(text, n, "tool id out of range%s", "");
  /* The text is network input: bounded by the type, NUL-terminated by the
   * deserializer, but check the bound again before treating it as a name. */
  if (!memchr(c->text, 0, sizeof c->text)) return refuse(text, n, "station name not terminated%s", "");
  size_t t = (size_t)c->tool_id;
  return c->kind == viscera_CONTROL_ASSIGN_TOOL ? apply_assign(r, t, c->text, text, n) : apply_guide(r, t, c, text, n);
}

int tool_roles_valid(const tool_roles_t *r, size_t t, const char *owner, const char *guide, double a, double k) {
  if (t >= r->ntools) return -1;
  if (owner[0] && !station_name_valid(owner)) return -1;
  if (!guide[0]) return 0;
  if (!station_name_valid(guide) || !strcmp(guide, owner)) return -1;
  if (!isfinite(a) || a < 0 || a > 1 || !isfinite(k) || !(k > 0) || k > r->tool[t].max_coupling) return -1;
  return 0;
}

int tool_roles_restore(tool_roles_t *r, size_t t, const char *owner, const char *guide, double a, double k) {
  if (tool_roles_valid(r, t, owner, guide, a, k)) return -1;
  set_role(r, t, owner, guide, guide[0] ? a : 0, guide[0] ? k : 0);
  return 0;
}

void tool_roles_fill(const tool_roles_t *r, size_t t, uint64_t sim_time_ns, viscera_ToolRole *out) {
  memset(out, 0, sizeof *out);
  if (t >= r->ntools) return;
  const tool_role_t *tr = &r->tool[t];
  out->tool_id = (uint32_t)t;
  out->sim_time_ns = sim_time_ns;
  out->version = tr->version;
  snprintf(out->owner, sizeof out->owner, "%s", tr->owner);
  snprintf(out->guide, sizeof out->guide, "%s", tr->guide);
  out->authority = tr->guide[0] ? (float)tr->authority : 0.0f;
  out->coupling_stiffness = tr->guide[0] ? (float)tr->coupling : 0.0f;
}
