/* SPDX-License-Identifier: Apache-2.0 */
#include "training/measures_blob.h"

#include <math.h>

void measures_blob_put(state_blob_t *b, const thr_tracker_t *tr, uint32_t grasps, double grasp_time) {
  for (int k = 0; k < THR_COUNT; k++) {
    sb_put_f64(b, tr->time_above[k]);
    sb_put_u64(b, tr->crossings[k]);
  }
  sb_put_f64(b, tr->peak_force);
  sb_put_f64(b, tr->contact_time);
  sb_put_f64(b, tr->contact_force_integral);
  sb_put_f64(b, tr->path_length);
  sb_put_u64(b, grasps);
  sb_put_f64(b, grasp_time);
}

const char *measures_blob_get(state_blob_t *b, thr_tracker_t *tr, uint32_t *grasps, double *grasp_time) {
  for (int k = 0; k < THR_COUNT; k++) {
    tr->time_above[k] = sb_get_f64(b);
    tr->crossings[k] = (uint32_t)sb_get_u64(b);
  }
  tr->peak_force = sb_get_f64(b);
  tr->contact_time = sb_get_f64(b);
  tr->contact_force_integral = sb_get_f64(b);
  tr->path_length = sb_get_f64(b);
  double sum = tr->peak_force + tr->contact_time + tr->contact_force_integral + tr->path_length;
  for (int k = 0; k < THR_COUNT; k++) sum += tr->time_above[k];
  if (!isfinite(sum) || tr->peak_force < 0 || tr->contact_time < 0 || tr->path_length < 0) return "bad tool measures";
  uint64_t g = sb_get_u64(b);
  double gt = sb_get_f64(b);
  if (g > UINT32_MAX || !isfinite(gt) || gt < 0) return "bad tool tally";
  *grasps = (uint32_t)g;
  *grasp_time = gt;
  return NULL;
}
