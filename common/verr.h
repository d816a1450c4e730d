/* SPDX-License-Identifier: Apache-2.0 */
/* verr: one error-message style for the whole product.
 * Library code never exits or prints on failure: it fills a verr_t naming the
 * file, line or field at fault and returns a negative code. main() prints it. */
#ifndef VISCERA_VERR_H
#define VISCERA_VERR_H

#include <stddef.h>

#define VERR_MSG_LEN 512

typedef struct verr {
  char msg[VERR_MSG_LEN];
} verr_t;

/* printf-style; safe with err == NULL. Always returns -1 so callers can
 * `return verr_set(err, ...)`. */
int verr_set(verr_t *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
