/* SPDX-License-Identifier: Apache-2.0 */
/* camera: a fixed perspective camera that frames a bounding box, and the
 * projection of scene points to window pixels.
 *
 * The scene is z-up (metres). camera_frame() looks at the box centre from the
 * front (-y side) and above, at CAMERA_ELEVATION_DEG, from far enough that the
 * box's bounding sphere fits the narrower field of view with a margin. The
 * viewer calls it once, so every frame of a run shares one view and frames are
 * comparable. Matrices are column-major floats, ready for glLoadMatrixf, and
 * camera_project() uses the same matrices, so a projected point lands on the
 * pixel the renderer drew it at. Plain data: no allocation, thread-safe. */
#ifndef VISCERA_VIEWER_CAMERA_H
#define VISCERA_VIEWER_CAMERA_H

/* Elevation above the horizontal and azimuth from the -y axis towards +x.
 * A small azimuth shows organ and tool shaft as solids instead of outlines. */
#define CAMERA_ELEVATION_DEG 35.0
#define CAMERA_AZIMUTH_DEG 20.0
/* Vertical field of view. */
#define CAMERA_FOVY_DEG 30.0

typedef struct camera {
  int width, height; /* window in pixels */
  double eye[3];     /* m */
  double target[3];  /* m, the box centre */
  double radius;     /* m, bounding-sphere radius that was framed */
  float view[16];    /* world -> eye, column-major */
  float proj[16];    /* eye -> clip, column-major */
} camera_t;

/* Frames the box [bmin, bmax] in a width x height window. Returns 0, or -1
 * when the size is not positive or the box is not finite (then *c is left
 * unchanged). A degenerate (flat or point) box is framed as a small sphere. */
int camera_frame(camera_t *c, const double bmin[3], const double bmax[3], int width, int height);

/* Window pixel coordinates of p: x to the right, y down from the top-left
 * corner (PNG order), pixel centres at +0.5. Returns 1, or 0 when p is behind
 * the eye or not finite (then px, py are -1). Points outside the window
 * still project (coordinates outside [0, width) x [0, height)). */
int camera_project(const camera_t *c, const double p[3], double *px, double *py);

#endif
