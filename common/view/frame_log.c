/* SPDX-License-Identifier: Apache-2.0 */
#include "view/frame_log.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

/* mkdir -p: each prefix in turn; an existing directory is fine. */
static int make_dirs(const char *dir, verr_t *err) {
  char p[FRAME_LOG_DIR_LEN];
  if (snprintf(p, sizeof p, "%s", dir) >= (int)sizeof p) return verr_set(err, "%s: path too long", dir);
  for (char *s = p + 1;; s++) {
    if (*s != '/' && *s != 0) continue;
    char saved = *s;
    *s = 0;
    if (mkdir(p, 0777) != 0 && errno != EEXIST)
      return verr_set(err, "%s: cannot create directory: %s", p, strerror(errno));
    *s = saved;
    if (!saved) break;
  }
  struct stat st;
  if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) return verr_set(err, "%s: not a directory", dir);
  return 0;
}

int frame_log_open(frame_log_t *fl, const char *dir, verr_t *err) {
  memset(fl, 0, sizeof *fl);
  if (make_dirs(dir, err)) return -1;
  snprintf(fl->dir, sizeof fl->dir, "%s", dir);
  char path[sizeof fl->dir + 16];
  snprintf(path, sizeof path, "%s/frames.csv", dir);
  fl->csv = fopen(path, "w");
  if (!fl->csv) return verr_set(err, "%s: cannot open for writing: %s", path, strerror(errno));
  fprintf(fl->csv, "%s\n", FRAME_LOG_HEADER);
  if (fflush(fl->csv) != 0) {
    fclose(fl->csv);
    fl->csv = NULL;
    return verr_set(err, "%s: write failed", path);
  }
  return 0;
}

int frame_log_next_path(const frame_log_t *fl, char *buf, size_t size, verr_t *err) {
  if (snprintf(buf, size, "%s/frame_%05ld.png", fl->dir, fl->frames) >= (int)size)
    return verr_set(err, "%s: path too long", fl->dir);
  return 0;
}

static void put_px(FILE *f, int known, double v) {
  if (known)
    fprintf(f, ",%.1f", v);
  else
    fputs(",-1", f);
}

int frame_log_add(frame_log_t *fl, const frame_row_t *r, verr_t *err) {
  fprintf(fl->csv, "%ld,frame_%05ld.png,%.1f,", fl->frames, fl->frames, r->wall_ms);
  if (r->sim_time_s >= 0)
    fprintf(fl->csv, "%.6f", r->sim_time_s);
  else
    fputs("-1", fl->csv);
  fprintf(fl->csv, ",%lld,%d,%.4f", r->frame_seq, r->in_contact ? 1 : 0, r->force_n);
  put_px(fl->csv, r->tool_known, r->tool_px);
  put_px(fl->csv, r->tool_known, r->tool_py);
  put_px(fl->csv, r->proxy_known, r->proxy_px);
  put_px(fl->csv, r->proxy_known, r->proxy_py);
  fputc('\n', fl->csv);
  if (fflush(fl->csv) != 0 || ferror(fl->csv)) return verr_set(err, "%s/frames.csv: write failed", fl->dir);
  fl->frames++;
  return 0;
}

int frame_log_close(frame_log_t *fl, verr_t *err) {
  if (!fl->csv) return 0;
  int rc = fclose(fl->csv);
  fl->csv = NULL;
  return rc ? verr_set(err, "%s/frames.csv: close failed", fl->dir) : 0;
}
