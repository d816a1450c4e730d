/* SPDX-License-Identifier: Apache-2.0 */
/* text_scan: a whitespace-token reader over a whole text file, for the
 * line-oriented mesh formats (gmsh, VTK legacy, TetGen). Every token knows
 * its line, so a parser can say "file.msh:12: ..." about what it refused.
 *
 * Ownership: text_scan_open() reads the whole file into memory the scanner
 * owns (at most TEXT_SCAN_MAX_BYTES, so a hostile file cannot exhaust
 * memory); text_scan_close() frees it. Single-threaded. Comments starting
 * with `comment` (0: none) run to the end of their line and are skipped. */
#ifndef VISCERA_TEXT_SCAN_H
#define VISCERA_TEXT_SCAN_H

#include <stddef.h>

#include "verr.h"

#define TEXT_SCAN_MAX_BYTES ((size_t)512 << 20)
#define TEXT_SCAN_TOKEN_MAX 128

typedef struct text_scan {
  char *buf;
  size_t len, pos;
  int line;     /* line of the next unread character, from 1 */
  int tok_line; /* line of the last token returned */
  char comment;
  const char *path;
  char tok[TEXT_SCAN_TOKEN_MAX];
} text_scan_t;

int text_scan_open(text_scan_t *s, const char *path, char comment, verr_t *err);
void text_scan_close(text_scan_t *s);
/* The next token into s->tok; returns 0, 1 at the end of the file, or -1
 * with err set when a token is longer than TEXT_SCAN_TOKEN_MAX - 1 or holds
 * a NUL byte (a binary file). */
int text_scan_next(text_scan_t *s, verr_t *err);
/* Tokens on the rest of the current line are dropped. */
void text_scan_skip_line(text_scan_t *s);
/* The rest of the current line and its newline are dropped: the next
 * token is read from the following line, whatever it holds. */
void text_scan_next_line(text_scan_t *s);
/* 1 when only blanks remain before the next newline (or the end). */
int text_scan_at_eol(const text_scan_t *s);
/* The next token, which must be present, as a number. `what` names it in
 * messages ("node 4 x"). Integers: a whole number within [lo, hi]. */
int text_scan_double(text_scan_t *s, const char *what, double *out, verr_t *err);
int text_scan_long(text_scan_t *s, const char *what, long long lo, long long hi, long long *out, verr_t *err);
/* The next token must equal word (e.g. "$EndNodes"). */
int text_scan_expect(text_scan_t *s, const char *word, verr_t *err);
/* err = "PATH:LINE: message", the line of the last token. */
int text_scan_fail(const text_scan_t *s, verr_t *err, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

#endif
