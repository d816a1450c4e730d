/* seat: what the dashboard follows of one seat: the scene (scene_view.h:
 * organs, tools, contact force), the seat's SessionEvents (threshold
 * crossings, lost clients) and a short history of the trainee's force.
 *
 * Every sample is untrusted (scene_view validates meshes and tools; events
 * are only counted and their levels checked). Not thread-safe. */
#ifndef VISCERA_DASHBOARD_SEAT_H
#define VISCERA_DASHBOARD_SEAT_H

#include <stdint.h>

#include "camera.h"
#include "scene_view.h"

#define SEAT_HISTORY 600      /* force samples kept (60 s at 10 Hz) */
#define SEAT_ALERT_HOLD_S 3.0 /* an alert stays up this long after its crossing */

typedef enum seat_alert { SEAT_OK, SEAT_ABOVE_ST, SEAT_ABOVE_MPF, SEAT_ABOVE_SFT } seat_alert_t;

typedef struct seat {
  char partition[128];
  scene_view_t sv;
  dds_entity_t rd_event;
  int have_camera;
  camera_t cam;
  float history[SEAT_HISTORY]; /* N, newest at (nhist - 1) % SEAT_HISTORY */
  uint64_t nhist;
  float peak;            /* N since the dashboard started */
  seat_alert_t alert;    /* highest level crossed up within SEAT_ALERT_HOLD_S */
  double alert_until;    /* dashboard time (s) the alert shows until */
  uint32_t crossings[3]; /* upward crossings seen: ST, MPF, SFT */
  int client_lost;       /* a CLIENT_LOST event since the last contact */
} seat_t;

int seat_open(seat_t *s, int domain, const char *partition, verr_t *err);
void seat_close(seat_t *s);
/* Takes what arrived; `now` is the dashboard's clock in s. */
int seat_poll(seat_t *s, double now, verr_t *err);
/* Records the primary tool's force (N) into the history. */
void seat_sample(seat_t *s);
/* The primary tool's current force (N) and thresholds; 0 when none. */
double seat_force(const seat_t *s, float *st, float *mpf, float *sft, float *max_force);

#endif
