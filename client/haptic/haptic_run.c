/* SPDX-License-Identifier: Apache-2.0 */
#include "haptic_run.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>

#include "haptic_dds.h"
#include "haptic_loop.h"
#include "haptic_summary.h"
#include "vrt.h"
#include "vsignal.h"

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int sig) {
  (void)sig;
  g_stop = 1;
}

/* The loop's output file and buffers; 0, or 1 after a message. */
static int open_outputs(const haptic_options_t *o, FILE **csv, haptic_stats_t *st, guide_report_t *guide) {
  if (o->force_csv) {
    *csv = fopen(o->force_csv, "w");
    if (!*csv) {
      fprintf(stderr, "viscera-haptic: %s: cannot open for writing\n", o->force_csv);
      return 1;
    }
    fprintf(*csv, "t,x,y,z,fx,fy,fz,in_contact,energy_j,step_n\n");
  }
  /* A 1 kHz loop sharing two cores with physics and rendering misses its
   * tick whenever the scheduler prefers them; SCHED_FIFO and locked pages
   * keep the period. DDS threads stay at normal priority (vrt.h). */
  if (o->rt_priority) vrt_make_realtime(o->rt_priority, "haptic", "loop", o->quiet, stderr);
  st->period_us = malloc(st->cap * sizeof(double));
  if (!st->period_us || guide_report_init(guide, st->cap)) {
    fprintf(stderr, "viscera-haptic: out of memory\n");
    return 1;
  }
  return 0;
}

int haptic_run(const haptic_options_t *o) {
  verr_t err;
  device_t dev;
  if (device_open(&dev, o->device, &o->dcfg, &err)) {
    fprintf(stderr, "viscera-haptic: %s\n", err.msg);
    return 1;
  }
  static haptic_dds_t h;
  double cap_s = o->duration >= 0 ? o->duration + 1 : 600;
  size_t cap = (size_t)fmin(1e7, fmax(1000, o->rate * cap_s));
  if (haptic_dds_open(&h, o, cap)) {
    dev.ops->close(&dev);
    return 1;
  }
  vsignal_on_stop(on_signal, 0);
  /* Wait for the scene so the script starts when the server can answer. */
  if (!haptic_dds_wait_scene(&h, o, &g_stop) && !g_stop) {
    haptic_dds_close(&h);
    dev.ops->close(&dev);
    return 1;
  }
  FILE *csv = NULL;
  haptic_stats_t st = {.cap = cap};
  guide_report_t guide = {0};
  if (open_outputs(o, &csv, &st, &guide)) return 1;
  haptic_loop_t loop = {.o = o, .dev = &dev, .h = &h, .csv = csv, .guide = &guide, .st = &st, .stop = &g_stop};
  haptic_loop_run(&loop);
  haptic_summary_print(o, &st, &h, &guide);
  free(st.period_us);
  guide_report_free(&guide);
  haptic_dds_close(&h);
  dev.ops->close(&dev);
  return 0;
}
