/* SPDX-License-Identifier: Apache-2.0 */
/* seat: what the dashboard follows of one seat: the scene (scene_view.h:
 * organs, tools, contact force), the seat's SessionEvents (threshold
 * crossings, lost clients, instructor commands; the last SEAT_EVENTS kept
 * for the focus view), who drives each tool (ToolRole), the server's
 * per-tool measures (ToolMetrics: peak, time above each threshold) and a
 * short history of the trainee's force.
 *
 * Every sample is untrusted (scene_view validates meshes and tools; events
 * are counted, their levels checked and their text cleaned; roles and
 * measures with an out-of-range tool or a non-finite number are dropped and
 * counted in `rejected`). Not thread-safe. */
#ifndef VISCERA_DASHBOARD_SEAT_H
#define VISCERA_DASHBOARD_SEAT_H

#include <stdint.h>

#include "view/camera.h"
#include "dds/vdds_gate.h"
#include "view/scene_view.h"
#include "seat_text.h"

/* SEAT_ALERT_HOLD_S: an alert stays up this long after its crossing, both in
 * the dashboard's time and in the seat's simulated time. */
#define SEAT_HISTORY 600      /* force samples kept (60 s at 10 Hz) */
#define SEAT_ALERT_HOLD_S 3.0 /* s */
#define SEAT_EVENTS 8         /* events kept for the focus view */

/* One SessionEvent as the focus view lists it. */
typedef struct seat_event {
  double sim_s; /* the server's simulated time */
  int kind;     /* viscera_EventKind */
  char text[160];
} seat_event_t;

/* A tool's ToolRole (idl). */
typedef struct seat_role {
  int have;
  int changed; /* set when a sample changes it; the caller clears it */
  char owner[33], guide[33];
  float authority;
} seat_role_t;

/* A tool's ToolMetrics, the measures the dashboard shows. */
typedef struct seat_tool_measures {
  int have;
  double peak;     /* N */
  double above[3]; /* s above ST, MPF, SFT */
} seat_tool_measures_t;

typedef struct seat {
  char partition[128];
  scene_view_t sv;
  dds_entity_t rd_event, rd_role, rd_measures;      /* believed from the seat's server only (sv.server) */
  vdds_gate_t gate_event, gate_role, gate_measures; /* bounded: source 0, the tools */
  dds_entity_t rd_presence;                         /* ToolCommand, read for its instance states only (seat_presence) */
  int have_camera;
  camera_t cam;
  float history[SEAT_HISTORY]; /* N, newest at (nhist - 1) % SEAT_HISTORY */
  uint64_t nhist;
  float peak;                       /* N since the dashboard started */
  seat_alert_t alert;               /* highest level crossed up within SEAT_ALERT_HOLD_S, or the force's level now */
  double alert_until;               /* dashboard time (s) the alert shows until */
  double alert_sim_s;               /* the server's simulated time of the crossing behind the alert */
  uint32_t crossings[3];            /* upward crossings seen: ST, MPF, SFT */
  int client_lost;                  /* the trainee's client is gone without a goodbye (see below) */
  int client_left;                  /* it exited cleanly: its ToolCommand instance was disposed */
  int paused;                       /* the instructor paused the seat: its server applied a pause, no resume since */
  uint32_t paused_gen;              /* the server (seat_server generation) that applied it: a new one is not paused */
  seat_event_t events[SEAT_EVENTS]; /* newest at (nevents - 1) % SEAT_EVENTS */
  uint64_t nevents;
  seat_role_t roles[SCENE_VIEW_MAX_TOOLS];
  seat_tool_measures_t measures[SCENE_VIEW_MAX_TOOLS];
  double above_seen[3]; /* s above ST, MPF, SFT in this dashboard's samples */
  unsigned long rejected;
} seat_t;

/* Left or lost: a client that exits cleanly deletes its ToolCommand writer
 * while the writer is alive (it unregisters and disposes its instance): the
 * seat's reader sees the alive count drop with no not-alive rise, and the
 * seat shows "left", in grey. A client that dies (kill, crash, cable) stops
 * asserting liveliness: its lease expires (the not-alive count rises) and
 * the server's CLIENT_LOST event follows: the seat shows "lost", in red. (The
 * instance state cannot tell them apart: Cyclone auto-disposes a lost
 * writer's instances too.) A clean exit seen before or after the server's
 * event wins (the server's event for a deleted writer says "left" as well);
 * a new command or contact clears both. */
int seat_open(seat_t *s, int domain, const char *partition, verr_t *err);
void seat_close(seat_t *s);
/* Takes what arrived; `now` is the dashboard's clock in s. */
int seat_poll(seat_t *s, double now, verr_t *err);
/* Records the primary tool's force (N) into the history; dt (s) since the
 * previous sample counts towards the time above each threshold reached. */
void seat_sample(seat_t *s, double dt);
/* The tool the dashboard follows: the viewer's primary tool (the lowest
 * id with a pose or contact), else the first tool of the scene, so its
 * thresholds and role stay on show while no client drives it; -1 when the
 * scene has none. */
int seat_tool(const seat_t *s);
/* That tool's current force (N, 0 out of contact) and thresholds; 0 when none. */
double seat_force(const seat_t *s, float *st, float *mpf, float *sft, float *max_force);
/* The k-th newest kept event (k = 0 newest), or NULL. */
const seat_event_t *seat_event(const seat_t *s, unsigned k);

#endif
