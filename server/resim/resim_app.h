/* SPDX-License-Identifier: Apache-2.0 */
/* resim_app: what viscera-resim does once its command line is parsed. */
#ifndef VISCERA_RESIM_APP_H
#define VISCERA_RESIM_APP_H

#include <stddef.h>

typedef struct resim_options {
  const char *scene_path; /* --scene FILE, or NULL: the recording's own scene */
  const char *mesh_dir;   /* --mesh-dir DIR, or NULL */
  const char *csv_path;   /* --csv FILE, or NULL */
  const char *rec_path;   /* the recording */
  double tolerance;       /* --tolerance, m; < 0: quant_step/2 + float slack */
  int quiet;              /* --quiet */
  const char *partition;  /* --partition P, or NULL: the recording's only session */
  size_t run;             /* --run N: the session's Nth server run; 0: the last (resim_session.h) */
} resim_options_t;

/* Exit code: 0 within tolerance, 1 beyond, 2 on an error. */
int resim_app_run(const resim_options_t *o);

#endif
