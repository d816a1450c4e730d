/* SPDX-License-Identifier: Apache-2.0 */
#include "verdict.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measure_table.h"

void rep_limits_default(rep_limits_t *ls) {
  memset(ls, 0, sizeof *ls);
  static const char *const DEFAULTS[] = {"peak_force_N <= SFT", "time_above_SFT_s <= 0", "time_above_MPF_s <= 1"};
  for (size_t i = 0; i < sizeof DEFAULTS / sizeof DEFAULTS[0]; i++) rep_limits_add(ls, DEFAULTS[i], NULL);
}

static const char *skip_space(const char *s) {
  while (*s == ' ' || *s == '\t') s++;
  return s;
}

/* "1.5", "SFT", "1.2*MPF", "1.2 * MPF" */
static int parse_bound(const char *s, double *bound, int *level) {
  s = skip_space(s);
  char *end = NULL;
  double f = 1;
  errno = 0;
  double v = strtod(s, &end);
  if (end != s && errno == 0 && isfinite(v)) {
    s = skip_space(end);
    if (!*s) {
      *bound = v, *level = -1;
      return 0;
    }
    if (*s != '*') return -1;
    f = v;
    s = skip_space(s + 1);
  }
  for (int k = 0; k < THR_COUNT; k++) {
    size_t len = strlen(thr_name((thr_id_t)k));
    if (strncmp(s, thr_name((thr_id_t)k), len) == 0 && !*skip_space(s + len)) {
      *bound = f, *level = k;
      return 0;
    }
  }
  return -1;
}

int rep_limits_add(rep_limits_t *ls, const char *line, verr_t *err) {
  const char *s = skip_space(line);
  size_t klen = strcspn(s, " \t<>=");
  const char *op = skip_space(s + klen);
  bool upper;
  if (strncmp(op, "<=", 2) == 0)
    upper = true;
  else if (strncmp(op, ">=", 2) == 0)
    upper = false;
  else
    return verr_set(err, "limit '%s': expected MEASURE <= BOUND or MEASURE >= BOUND", line);
  int m = -1;
  for (int i = 0; i < REP_NMEASURES; i++)
    if (strlen(rep_measure(i)->key) == klen && strncmp(rep_measure(i)->key, s, klen) == 0) m = i;
  if (m < 0)
    return verr_set(err, "limit '%s': unknown measure '%.*s' (the report.csv column names)", line, (int)klen, s);
  rep_limit_t l = {.measure = m, .upper = upper};
  if (parse_bound(op + 2, &l.bound, &l.level) < 0)
    return verr_set(err, "limit '%s': the bound must be a number, ST, MPF or SFT, or FACTOR*MPF", line);
  snprintf(l.text, sizeof l.text, "%s %s %s", rep_measure(m)->key, upper ? "<=" : ">=", skip_space(op + 2));
  for (int i = 0; i < ls->n; i++)
    if (ls->l[i].measure == m && ls->l[i].upper == upper) {
      ls->l[i] = l;
      return 0;
    }
  if (ls->n >= REP_MAX_LIMITS) return verr_set(err, "limit '%s': at most %d limits", line, REP_MAX_LIMITS);
  ls->l[ls->n++] = l;
  return 0;
}

int rep_limits_load(rep_limits_t *ls, const char *path, verr_t *err) {
  FILE *f = fopen(path, "r");
  if (!f) return verr_set(err, "%s: %s", path, strerror(errno));
  memset(ls, 0, sizeof *ls);
  char line[512];
  int no = 0, ret = 0;
  while (ret == 0 && fgets(line, sizeof line, f)) {
    no++;
    line[strcspn(line, "#\r\n")] = 0;
    if (!*skip_space(line)) continue;
    verr_t e = {{0}};
    if (rep_limits_add(ls, line, &e) < 0) ret = verr_set(err, "%s:%d: %s", path, no, e.msg);
  }
  fclose(f);
  return ret;
}

rep_outcome_t rep_limit_check(const rep_limit_t *l, const rep_recording_t *r, double *value, double *bound) {
  double v = rep_measure_value(r, l->measure);
  double b = l->bound;
  if (l->level >= 0) b = r->sum.levels[l->level] > 0 ? l->bound * r->sum.levels[l->level] : NAN;
  *value = v;
  *bound = b;
  if (!isfinite(v) || !isfinite(b)) return REP_NA;
  /* Values are shown rounded; compare at that precision so a displayed
   * "0.80 <= 0.80" never fails on the last bit. */
  double tol = 1e-9 * fmax(1, fabs(b));
  return (l->upper ? v <= b + tol : v >= b - tol) ? REP_PASS : REP_FAIL;
}

rep_outcome_t rep_verdict(const rep_limits_t *ls, const rep_recording_t *r, int *nfail) {
  int fail = 0, pass = 0;
  for (int i = 0; i < ls->n; i++) {
    double v, b;
    rep_outcome_t o = rep_limit_check(&ls->l[i], r, &v, &b);
    fail += o == REP_FAIL;
    pass += o == REP_PASS;
  }
  if (nfail) *nfail = fail;
  return fail ? REP_FAIL : pass ? REP_PASS : REP_NA;
}

const char *rep_outcome_name(rep_outcome_t o) { return o == REP_PASS ? "PASS" : o == REP_FAIL ? "FAIL" : "n/a"; }
