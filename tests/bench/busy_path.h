/* SPDX-License-Identifier: Apache-2.0 */
/* busy_path: load_bench.sh --busy's probe path, for the benchmarks that
 * drive a runtime without DDS (bench_seats, bench_drive): down 8 mm in
 * 0.5 s at x 12 mm, y 4 mm (the classroom organs' top is at z 35 mm), then
 * sweeping 5 mm either side every 2 s without letting go. */
#ifndef VISCERA_BUSY_PATH_H
#define VISCERA_BUSY_PATH_H

#include <math.h>

/* The probe's target at simulated time t (s), in m. */
static inline void busy_target(double t, double p[3]) {
  p[1] = 0.004;
  if (t < 0.5) {
    p[0] = 0.012;
    p[2] = 0.07 + (0.027 - 0.07) * t / 0.5;
    return;
  }
  p[2] = 0.027;
  if (t < 1.0) {
    p[0] = 0.012 + 0.005 * (t - 0.5) / 0.5;
    return;
  }
  double ph = fmod(t - 1.0, 2.0); /* 1 s to x = 7 mm, 1 s back to 17 mm */
  p[0] = ph < 1.0 ? 0.017 - 0.010 * ph : 0.007 + 0.010 * (ph - 1.0);
}

#endif
