/* SPDX-License-Identifier: Apache-2.0 */
#include "text_scan.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int text_scan_open(text_scan_t *s, const char *path, char comment, verr_t *err) {
  memset(s, 0, sizeof *s);
  s->path = path;
  s->line = s->tok_line = 1;
  s->comment = comment;
  FILE *f = fopen(path, "rb");
  if (!f) return verr_set(err, "%s: cannot open: %s", path, strerror(errno));
  size_t cap = 1 << 16;
  s->buf = malloc(cap);
  while (s->buf) {
    size_t got = fread(s->buf + s->len, 1, cap - s->len, f);
    s->len += got;
    if (got == 0) break;
    if (s->len == cap) {
      if (cap >= TEXT_SCAN_MAX_BYTES) {
        fclose(f);
        text_scan_close(s);
        return verr_set(err, "%s: larger than %zu MB, refused", path, TEXT_SCAN_MAX_BYTES >> 20);
      }
      char *nb = realloc(s->buf, cap * 2);
      if (!nb) break;
      s->buf = nb;
      cap *= 2;
    }
  }
  int bad = ferror(f) || !s->buf;
  fclose(f);
  if (bad) {
    text_scan_close(s);
    return verr_set(err, "%s: cannot read (I/O error or out of memory)", path);
  }
  return 0;
}

void text_scan_close(text_scan_t *s) {
  free(s->buf);
  s->buf = NULL;
  s->len = s->pos = 0;
}

static int is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/* Skips blanks, newlines and comments. */
static void skip_space(text_scan_t *s) {
  while (s->pos < s->len) {
    char c = s->buf[s->pos];
    if (c == '\n') {
      s->line++;
      s->pos++;
    } else if (is_blank(c)) {
      s->pos++;
    } else if (s->comment && c == s->comment) {
      while (s->pos < s->len && s->buf[s->pos] != '\n') s->pos++;
    } else {
      break;
    }
  }
}

int text_scan_next(text_scan_t *s, verr_t *err) {
  skip_space(s);
  if (s->pos >= s->len) return 1;
  s->tok_line = s->line;
  size_t n = 0;
  while (s->pos < s->len) {
    char c = s->buf[s->pos];
    if (c == '\n' || is_blank(c) || (s->comment && c == s->comment)) break;
    if (c == '\0') return text_scan_fail(s, err, "a NUL byte: binary data where text was expected");
    /* Any other control byte is binary data too; naming it (not echoing the
     * token) keeps escape sequences from a random file off the terminal. */
    if ((unsigned char)c < 0x20 || c == 0x7f)
      return text_scan_fail(s, err, "a control byte 0x%02x: binary data where text was expected", (unsigned char)c);
    if (n + 1 >= TEXT_SCAN_TOKEN_MAX)
      return text_scan_fail(s, err, "a token longer than %d characters", TEXT_SCAN_TOKEN_MAX - 1);
    s->tok[n++] = c;
    s->pos++;
  }
  s->tok[n] = '\0';
  return 0;
}

void text_scan_skip_line(text_scan_t *s) {
  while (s->pos < s->len && s->buf[s->pos] != '\n') s->pos++;
}

void text_scan_next_line(text_scan_t *s) {
  text_scan_skip_line(s);
  if (s->pos < s->len) {
    s->pos++;
    s->line++;
  }
}

int text_scan_at_eol(const text_scan_t *s) {
  for (size_t i = s->pos; i < s->len; i++) {
    char c = s->buf[i];
    if (c == '\n') return 1;
    if (s->comment && c == s->comment) return 1;
    if (!is_blank(c)) return 0;
  }
  return 1;
}

static int need(text_scan_t *s, const char *what, verr_t *err) {
  int rc = text_scan_next(s, err);
  if (rc < 0) return -1;
  if (rc > 0) {
    s->tok_line = s->line;
    return text_scan_fail(s, err, "the file ends where %s was expected", what);
  }
  return 0;
}

int text_scan_double(text_scan_t *s, const char *what, double *out, verr_t *err) {
  if (need(s, what, err)) return -1;
  char *end;
  errno = 0;
  double v = strtod(s->tok, &end);
  if (end == s->tok || *end) return text_scan_fail(s, err, "%s: '%s' is not a number", what, s->tok);
  if (!isfinite(v) || errno == ERANGE)
    return text_scan_fail(s, err, "%s: '%s' is not a finite number in range", what, s->tok);
  *out = v;
  return 0;
}

int text_scan_long(text_scan_t *s, const char *what, long long lo, long long hi, long long *out, verr_t *err) {
  if (need(s, what, err)) return -1;
  char *end;
  errno = 0;
  long long v = strtoll(s->tok, &end, 10);
  if (end == s->tok || *end) return text_scan_fail(s, err, "%s: '%s' is not a whole number", what, s->tok);
  if (errno == ERANGE || v < lo || v > hi)
    return text_scan_fail(s, err, "%s: %s is outside [%lld, %lld]", what, s->tok, lo, hi);
  *out = v;
  return 0;
}

int text_scan_expect(text_scan_t *s, const char *word, verr_t *err) {
  if (need(s, word, err)) return -1;
  if (strcmp(s->tok, word)) return text_scan_fail(s, err, "expected '%s', found '%s'", word, s->tok);
  return 0;
}

int text_scan_fail(const text_scan_t *s, verr_t *err, const char *fmt, ...) {
  char msg[VERR_MSG_LEN];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return verr_set(err, "%s:%d: %s", s->path, s->tok_line, msg);
}
