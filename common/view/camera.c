/* SPDX-License-Identifier: Apache-2.0 */
#include "view/camera.h"

#include <math.h>

#include "vmath.h"

#define DEG (3.14159265358979323846 / 180.0)

/* Headroom around the bounding sphere so silhouettes never touch the border. */
#define FRAME_MARGIN 1.08
/* Smallest radius framed, for a single point or an empty-looking box (m). */
#define MIN_RADIUS 1e-3

static void mat_mul4(double *r, const double *a, const double *b) {
  for (int col = 0; col < 4; col++)
    for (int row = 0; row < 4; row++) {
      double s = 0;
      for (int k = 0; k < 4; k++) s += a[k * 4 + row] * b[col * 4 + k];
      r[col * 4 + row] = s;
    }
}

int camera_frame(camera_t *c, const double bmin[3], const double bmax[3], int width, int height) {
  if (width <= 0 || height <= 0 || !v3_isfinite(bmin) || !v3_isfinite(bmax)) return -1;
  camera_t n = {.width = width, .height = height};
  double half[3];
  for (int k = 0; k < 3; k++) {
    n.target[k] = 0.5 * (bmin[k] + bmax[k]);
    half[k] = 0.5 * fabs(bmax[k] - bmin[k]);
  }
  n.radius = v3_norm(half);
  if (!(n.radius >= MIN_RADIUS)) n.radius = MIN_RADIUS;

  double aspect = (double)width / height;
  double half_fovy = 0.5 * CAMERA_FOVY_DEG * DEG;
  double half_fovx = atan(tan(half_fovy) * aspect);
  double half_min = half_fovx < half_fovy ? half_fovx : half_fovy;
  double dist = n.radius * FRAME_MARGIN / sin(half_min);

  double el = CAMERA_ELEVATION_DEG * DEG, az = CAMERA_AZIMUTH_DEG * DEG;
  double dir[3] = {sin(az) * cos(el), -cos(az) * cos(el), sin(el)};
  for (int k = 0; k < 3; k++) n.eye[k] = n.target[k] + dist * dir[k];

  /* Look-at with z up: s = right, u = up, f = forward (into the screen). */
  double f[3], s[3], u[3], zup[3] = {0, 0, 1};
  v3_sub(f, n.target, n.eye);
  v3_normalize(f);
  v3_cross(s, f, zup);
  v3_normalize(s);
  v3_cross(u, s, f);
  double view[16] = {s[0],
                     u[0],
                     -f[0],
                     0,
                     s[1],
                     u[1],
                     -f[1],
                     0,
                     s[2],
                     u[2],
                     -f[2],
                     0,
                     -v3_dot(s, n.eye),
                     -v3_dot(u, n.eye),
                     v3_dot(f, n.eye),
                     1};

  /* Near plane close to the eye because a tool may come between the camera
   * and the organ; 24-bit depth keeps the ratio far/near (~300) harmless. */
  double znear = 0.02 * dist, zfar = dist + 4.0 * n.radius;
  double fy = 1.0 / tan(half_fovy);
  double proj[16] = {fy / aspect,
                     0,
                     0,
                     0,
                     0,
                     fy,
                     0,
                     0,
                     0,
                     0,
                     (zfar + znear) / (znear - zfar),
                     -1,
                     0,
                     0,
                     2.0 * zfar * znear / (znear - zfar),
                     0};
  for (int i = 0; i < 16; i++) {
    n.view[i] = (float)view[i];
    n.proj[i] = (float)proj[i];
  }
  *c = n;
  return 0;
}

int camera_project(const camera_t *c, const double p[3], double *px, double *py) {
  *px = *py = -1;
  if (!v3_isfinite(p)) return 0;
  double v[16], pr[16], m[16];
  for (int i = 0; i < 16; i++) {
    v[i] = c->view[i];
    pr[i] = c->proj[i];
  }
  mat_mul4(m, pr, v);
  double clip[4];
  for (int row = 0; row < 4; row++) clip[row] = m[row] * p[0] + m[4 + row] * p[1] + m[8 + row] * p[2] + m[12 + row];
  if (!(clip[3] > 1e-12)) return 0;
  double nx = clip[0] / clip[3], ny = clip[1] / clip[3];
  *px = (nx * 0.5 + 0.5) * c->width;
  *py = (0.5 - ny * 0.5) * c->height;
  return 1;
}
