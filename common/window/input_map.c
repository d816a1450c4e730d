/* SPDX-License-Identifier: Apache-2.0 */
#include "window/input_map.h"

#include <math.h>
#include <string.h>

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void clamp_pos(input_state_t *s) {
  for (int k = 0; k < 3; k++) s->pos[k] = fmin(s->hi[k], fmax(s->lo[k], s->pos[k]));
}

/* Depth moves along the line of sight through the tip (eye -> tip), not the
 * camera axis, so the tip stays under the cursor while it goes deeper. */
static void move_depth(input_state_t *s, double d) {
  double r[3] = {s->pos[0] - s->eye[0], s->pos[1] - s->eye[1], s->pos[2] - s->eye[2]};
  double n = sqrt(dot3(r, r));
  for (int k = 0; k < 3; k++) s->pos[k] += d * (n > 1e-9 ? r[k] / n : s->fwd[k]);
  clamp_pos(s);
}

int input_map_init(input_state_t *s, const camera_t *c, const double bmin[3], const double bmax[3]) {
  for (int k = 0; k < 3; k++)
    if (!isfinite(bmin[k]) || !isfinite(bmax[k]) || bmin[k] > bmax[k]) return -1;
  memset(s, 0, sizeof *s);
  /* The camera's view matrix rows are the eye axes in world coordinates
   * (column-major: row i is view[i], view[4 + i], view[8 + i]): x right,
   * y up, z towards the viewer. */
  for (int k = 0; k < 3; k++) {
    s->right[k] = c->view[4 * k + 0];
    s->up[k] = c->view[4 * k + 1];
    s->fwd[k] = -c->view[4 * k + 2];
    s->eye[k] = c->eye[k];
  }
  s->px_per_rad = c->height / (2.0 * tan(CAMERA_FOVY_DEG * M_PI / 360.0));
  double diag = sqrt((bmax[0] - bmin[0]) * (bmax[0] - bmin[0]) + (bmax[1] - bmin[1]) * (bmax[1] - bmin[1]) +
                     (bmax[2] - bmin[2]) * (bmax[2] - bmin[2]));
  diag = fmax(diag, 0.01); /* a point or flat organ still gets room to move */
  for (int k = 0; k < 3; k++) {
    s->lo[k] = bmin[k] - diag;
    s->hi[k] = bmax[k] + diag;
    s->home[k] = 0.5 * (bmin[k] + bmax[k]);
  }
  s->home[2] = bmax[2] + INPUT_HOME_CLEARANCE;
  memcpy(s->pos, s->home, sizeof s->pos);
  return 0;
}

double input_map_metres_per_pixel(const input_state_t *s) {
  double d[3] = {s->pos[0] - s->eye[0], s->pos[1] - s->eye[1], s->pos[2] - s->eye[2]};
  double depth = dot3(d, s->fwd);
  /* Behind or at the eye (cannot happen inside the clamp box of a framed
   * scene, but the box is not the camera's business): a small floor. */
  return fmax(depth, 1e-3) / s->px_per_rad;
}

static void update_buttons(input_state_t *s) { s->buttons = (s->key_space || s->mouse_left) ? 1u : 0u; }

void input_map_apply(input_state_t *s, const input_event_t *e) {
  s->events++;
  switch (e->kind) {
  case INPUT_MOTION: {
    if (!isfinite(e->dx) || !isfinite(e->dy)) return;
    double m = input_map_metres_per_pixel(s);
    for (int k = 0; k < 3; k++) s->pos[k] += m * (e->dx * s->right[k] - e->dy * s->up[k]);
    clamp_pos(s);
    break;
  }
  case INPUT_WHEEL:
    move_depth(s, INPUT_WHEEL_STEP * e->n);
    break;
  case INPUT_KEY_DOWN:
  case INPUT_KEY_UP: {
    int down = e->kind == INPUT_KEY_DOWN;
    if (e->key == INPUT_KEY_W) s->key_w = down;
    if (e->key == INPUT_KEY_S) s->key_s = down;
    if (e->key == INPUT_KEY_SPACE) s->key_space = down;
    if (e->key == INPUT_KEY_R && down) memcpy(s->pos, s->home, sizeof s->pos);
    break;
  }
  case INPUT_BUTTON_DOWN:
  case INPUT_BUTTON_UP:
    s->mouse_left = e->kind == INPUT_BUTTON_DOWN;
    break;
  }
  update_buttons(s);
}

void input_map_advance(input_state_t *s, double dt) {
  if (!(dt > 0)) return;
  dt = fmin(dt, 0.1);
  int dir = s->key_w - s->key_s;
  if (dir) move_depth(s, dir * INPUT_KEY_SPEED * dt);
}
