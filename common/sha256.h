/* SPDX-License-Identifier: Apache-2.0 */
/* sha256: the SHA-256 digest (FIPS 180-4) of a buffer or a file, as 64
 * lowercase hex digits. Used to name the exact scene text and mesh files a
 * recording was made with (issue 16), so a re-simulation can tell whether
 * the files it finds are the ones the session ran. Pure, no global state. */
#ifndef VISCERA_SHA256_H
#define VISCERA_SHA256_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

#define SHA256_HEX_LEN 65 /* 64 digits and the NUL */

void sha256_hex(const void *data, size_t len, char out[SHA256_HEX_LEN]);
/* The digest of a whole file and its size in bytes; -1 with err naming the
 * file when it cannot be read. */
int sha256_file(const char *path, char out[SHA256_HEX_LEN], uint64_t *size, verr_t *err);

#endif
