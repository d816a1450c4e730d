/* SPDX-License-Identifier: Apache-2.0 */
/* roles_watch: waits until a running server shows a tool's role and where
 * the tool is, as the server publishes them (ToolRole, ContactFeedback).
 *
 * The role: the latest ToolRole sample of the tool (state topic: a new
 * participant gets it at once) must have the given version, owner, guide and
 * authority. The position: in free space the god-object proxy sits on the
 * tool position the server computed from its stations' commands, so
 * ContactFeedback.proxy_position is the server's tool position; it must stay
 * within `tol` of the expected point for `hold` ms of simulated time (a
 * tool still jumping between two stations never does).
 *
 * Prints "ROLE ..." and "AT ..." lines; exit 0 when both hold before the
 * timeout, 1 otherwise (with what was last seen), 2 on usage or DDS errors.
 * usage: roles_watch PARTITION TOOL [--version V] [--owner S] [--guide S]
 *          [--authority A] [--near X,Y,Z] [--tol M] [--hold MS] [--timeout S]
 * ("-" for an empty owner or guide). Domain from $VISCERA_DOMAIN. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/vdds.h"
#include "viscera.h"
#include "vtime.h"

typedef struct want {
  long version; /* -1: any */
  const char *owner, *guide;
  double authority; /* NaN: any */
  int near;
  double at[3], tol, hold_ms;
} want_t;

static int role_ok(const want_t *w, const viscera_ToolRole *r) {
  if (w->version >= 0 && r->version != (uint32_t)w->version) return 0;
  if (w->owner && strcmp(r->owner, w->owner)) return 0;
  if (w->guide && strcmp(r->guide, w->guide)) return 0;
  if (!isnan(w->authority) && fabs(r->authority - w->authority) > 1e-6) return 0;
  return 1;
}

static const char *empty(const char *s) { return strcmp(s, "-") ? s : ""; }

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: roles_watch PARTITION TOOL [options] (see the source)\n");
    return 2;
  }
  const char *partition = argv[1];
  uint32_t tool = (uint32_t)atoi(argv[2]);
  want_t w = {.version = -1, .authority = NAN, .tol = 5e-4, .hold_ms = 100};
  double timeout = 20;
  for (int i = 3; i + 1 < argc; i += 2) {
    const char *o = argv[i], *v = argv[i + 1];
    if (!strcmp(o, "--version"))
      w.version = atol(v);
    else if (!strcmp(o, "--owner"))
      w.owner = empty(v);
    else if (!strcmp(o, "--guide"))
      w.guide = empty(v);
    else if (!strcmp(o, "--authority"))
      w.authority = atof(v);
    else if (!strcmp(o, "--near"))
      w.near = sscanf(v, "%lf,%lf,%lf", &w.at[0], &w.at[1], &w.at[2]) == 3;
    else if (!strcmp(o, "--tol"))
      w.tol = atof(v);
    else if (!strcmp(o, "--hold"))
      w.hold_ms = atof(v);
    else if (!strcmp(o, "--timeout"))
      timeout = atof(v);
    else {
      fprintf(stderr, "roles_watch: unknown option %s\n", o);
      return 2;
    }
  }
  verr_t err;
  int domain = cli_env_domain(&err);
  vdds_t dds;
  if (domain < 0 || vdds_open(&dds, domain, partition, &err)) {
    fprintf(stderr, "roles_watch: %s\n", err.msg);
    return 2;
  }
  dds_entity_t r_role = vdds_reader(&dds, VT_TOOL_ROLE, &err), r_fb = vdds_reader(&dds, VT_CONTACT_FEEDBACK, &err);
  if (r_role < 0 || r_fb < 0) {
    fprintf(stderr, "roles_watch: %s\n", err.msg);
    vdds_close(&dds);
    return 2;
  }
  viscera_ToolRole role;
  memset(&role, 0, sizeof role);
  int have_role = 0, role_good = 0, pos_good = !w.near;
  double last[3] = {NAN, NAN, NAN};
  uint64_t run_start_ns = 0, last_sim = 0, nfb = 0;
  int in_run = 0;
  uint64_t deadline = vtime_mono_ns() + (uint64_t)(timeout * 1e9);
  while (vtime_mono_ns() < deadline && !(role_good && pos_good)) {
    void *s[8] = {0};
    dds_sample_info_t info[8];
    int n = dds_take(r_role, s, info, 8, 8);
    for (int i = 0; i < n; i++) {
      const viscera_ToolRole *m = s[i];
      if (!info[i].valid_data || m->tool_id != tool) continue;
      role = *m;
      have_role = 1;
      role_good = role_ok(&w, m);
    }
    if (n > 0) dds_return_loan(r_role, s, n);
    n = dds_take(r_fb, s, info, 8, 8);
    for (int i = 0; i < n; i++) {
      const viscera_ContactFeedback *f = s[i];
      if (!info[i].valid_data || f->tool_id != tool || f->sim_time_ns == last_sim) continue;
      last_sim = f->sim_time_ns;
      nfb++;
      double d2 = 0;
      for (int k = 0; k < 3; k++) {
        last[k] = f->proxy_position[k];
        d2 += (last[k] - w.at[k]) * (last[k] - w.at[k]);
      }
      /* Counted only once the role is the wanted one: the position must
       * follow the role, not an earlier state that happened to match. */
      if (!w.near || !role_good || f->in_contact || sqrt(d2) > w.tol) {
        in_run = 0;
        continue;
      }
      if (!in_run) {
        in_run = 1;
        run_start_ns = f->sim_time_ns;
      }
      if ((double)(f->sim_time_ns - run_start_ns) * 1e-6 >= w.hold_ms) pos_good = 1;
    }
    if (n > 0) dds_return_loan(r_fb, s, n);
    dds_sleepfor(DDS_MSECS(2));
  }
  if (have_role)
    printf("ROLE tool=%u version=%u owner=%s guide=%s authority=%.3f coupling=%.1f\n", tool, role.version,
           role.owner[0] ? role.owner : "-", role.guide[0] ? role.guide : "-", role.authority, role.coupling_stiffness);
  else
    printf("ROLE tool=%u none seen\n", tool);
  printf("AT %.5f %.5f %.5f (%llu feedback samples)\n", last[0], last[1], last[2], (unsigned long long)nfb);
  vdds_close(&dds);
  if (!role_good) fprintf(stderr, "roles_watch: the role was not the one wanted within %.1f s\n", timeout);
  if (!pos_good)
    fprintf(stderr, "roles_watch: the tool did not stay within %.2g m of %.4f,%.4f,%.4f for %.0f ms within %.1f s\n",
            w.tol, w.at[0], w.at[1], w.at[2], w.hold_ms, timeout);
  return role_good && pos_good ? 0 : 1;
}
