/* SPDX-License-Identifier: Apache-2.0 */
/* link_plot: the charts of link_bench.sh (issue 14). Reads its link.csv
 * (delay_ms,jitter_ms,loss_pct,reorder,peak_force_n,peak_error_pct,max_step_n,
 * energy_j,applied_pct,keyframe_ms,seat_kbps,viewer_kbps; the loopback row is
 * skipped) and writes one PNG per measure against the one-way delay, one
 * series per loss (colour) and reordering (solid: reordering, dashed: none):
 * link_peak_error.png, link_max_step.png, link_applied.png,
 * link_keyframe.png, link_bandwidth.png (seat solid, viewer dotted; no
 * reordering only), link_energy.png when the energy column has numbers.
 * usage: link_plot link.csv OUTDIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plot/plot.h"
#include "plot/plot_cleanup.h"

#define MAX_ROWS 256
#define NCOL 12

typedef struct row {
  double v[NCOL];
  int reorder;
} row_t;

static int load(const char *path, row_t *rows, int *n) {
  FILE *f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "link_plot: cannot open %s\n", path);
    return -1;
  }
  char line[512];
  *n = 0;
  while (fgets(line, sizeof line, f) && *n < MAX_ROWS) {
    if (strncmp(line, "delay_ms", 8) == 0 || strncmp(line, "loopback", 8) == 0) continue;
    row_t r;
    memset(&r, 0, sizeof r);
    char *save = NULL, *tok = strtok_r(line, ",\n", &save);
    for (int c = 0; tok && c < NCOL; c++, tok = strtok_r(NULL, ",\n", &save)) {
      if (c == 3)
        r.reorder = strcmp(tok, "yes") == 0;
      else
        r.v[c] = strcmp(tok, "-") == 0 ? NAN : strtod(tok, NULL);
    }
    rows[(*n)++] = r;
  }
  fclose(f);
  return 0;
}

/* One series per (loss, reorder) with measure column `col`; returns the number of finite points drawn. */
static int chart(const row_t *rows, int n, int col, const char *title, const char *ylabel, const char *dir,
                 const char *file, int only_no_reorder, int col2) {
  plot_t p;
  plot_init(&p, title, "one-way delay (ms)", ylabel, 0, 0);
  double losses[16];
  int nl = 0, finite = 0;
  for (int i = 0; i < n; i++) {
    int seen = 0;
    for (int k = 0; k < nl; k++) seen |= losses[k] == rows[i].v[2];
    if (!seen && nl < 16) losses[nl++] = rows[i].v[2];
  }
  for (int k = 0; k < nl; k++)
    for (int ro = 1; ro >= 0; ro--)
      for (int which = 0; which < (col2 >= 0 ? 2 : 1); which++) {
        if (only_no_reorder && ro) continue;
        double x[MAX_ROWS], y[MAX_ROWS];
        size_t m = 0;
        for (int i = 0; i < n; i++) {
          /* At 0 ms there is no jitter, so the one row stands for both. */
          if (rows[i].v[2] != losses[k] || (rows[i].reorder != ro && rows[i].v[0] > 0)) continue;
          x[m] = rows[i].v[0];
          y[m] = rows[i].v[which ? col2 : col];
          finite += isfinite(y[m]);
          m++;
        }
        if (!m) continue;
        char label[112];
        snprintf(label, sizeof label, "%g %% loss%s%s", losses[k], col2 >= 0 ? (which ? ", viewer" : ", seat") : "",
                 only_no_reorder ? "" : (ro ? ", reordering" : ", in order"));
        plot_add(&p, label, m, x, y, k, k, which ? PLOT_LINE_DOTTED : (ro ? PLOT_LINE_SOLID : PLOT_LINE_DASHED));
      }
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", dir, file);
  verr_t err;
  int rc = finite ? plot_write_png(&p, path, &err) : -1;
  if (finite && rc)
    fprintf(stderr, "link_plot: %s: %s\n", path, err.msg);
  else if (finite)
    printf("link_plot: %s\n", path);
  plot_free(&p);
  return finite;
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: link_plot link.csv OUTDIR\n");
    return 2;
  }
  static row_t rows[MAX_ROWS];
  int n;
  if (load(argv[1], rows, &n) || n == 0) return 1;
  const char *d = argv[2];
  chart(rows, n, 5, "Peak force error against loopback", "peak force error (%)", d, "link_peak_error.png", 0, -1);
  chart(rows, n, 6, "Largest one-tick force change", "force step (N)", d, "link_max_step.png", 0, -1);
  chart(rows, n, 8, "Commands applied by the server", "applied (% of sent)", d, "link_applied.png", 0, -1);
  chart(rows, n, 9, "Late joiner's keyframe wait (from match)", "wait (ms)", d, "link_keyframe.png", 0, -1);
  chart(rows, n, 10, "Bandwidth on the link", "kbit/s", d, "link_bandwidth.png", 1, 11);
  chart(rows, n, 7, "Passivity observer energy", "energy (J)", d, "link_energy.png", 0, -1);
  plot_cleanup();
  return 0;
}
