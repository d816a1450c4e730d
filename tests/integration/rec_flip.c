/* SPDX-License-Identifier: Apache-2.0 */
/* rec_flip: flips bits in one stored sample of a recording, the way one
 * damaged disk block or a bit error would (damaged_recordings_test.sh).
 *
 * usage: rec_flip DB TOPIC N BYTE MASK
 *   XORs MASK (0..255) into byte BYTE of the CDR of the N-th data sample
 *   (0-based, in storage order) of TOPIC. Exit 0, or 1 with a message. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sqlite3.h>

int main(int argc, char **argv) {
  if (argc != 6) {
    fprintf(stderr, "usage: rec_flip DB TOPIC N BYTE MASK\n");
    return 1;
  }
  sqlite3 *db = NULL;
  if (sqlite3_open(argv[1], &db) != SQLITE_OK) {
    fprintf(stderr, "rec_flip: %s: %s\n", argv[1], sqlite3_errmsg(db));
    return 1;
  }
  long n = atol(argv[3]), at = atol(argv[4]), mask = atol(argv[5]);
  sqlite3_stmt *st = NULL;
  int rc = 1;
  if (sqlite3_prepare_v2(db,
                         "SELECT s.id, s.cdr FROM samples s JOIN topics t ON t.id = s.topic_id WHERE t.name = ?1 "
                         "AND s.kind = 0 ORDER BY s.id LIMIT 1 OFFSET ?2",
                         -1, &st, NULL) == SQLITE_OK) {
    sqlite3_bind_text(st, 1, argv[2], -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 2, n);
    if (sqlite3_step(st) == SQLITE_ROW) {
      sqlite3_int64 id = sqlite3_column_int64(st, 0);
      int len = sqlite3_column_bytes(st, 1);
      unsigned char *cdr = malloc((size_t)len + 1);
      if (cdr && at >= 0 && at < len && mask > 0 && mask < 256) {
        memcpy(cdr, sqlite3_column_blob(st, 1), (size_t)len);
        cdr[at] ^= (unsigned char)mask;
        sqlite3_stmt *up = NULL;
        if (sqlite3_prepare_v2(db, "UPDATE samples SET cdr = ?1 WHERE id = ?2", -1, &up, NULL) == SQLITE_OK) {
          sqlite3_bind_blob(up, 1, cdr, len, SQLITE_TRANSIENT);
          sqlite3_bind_int64(up, 2, id);
          if (sqlite3_step(up) == SQLITE_DONE) {
            printf("rec_flip: %s sample %lld byte %ld ^= 0x%02lx\n", argv[2], (long long)id, at, mask);
            rc = 0;
          }
        }
        sqlite3_finalize(up);
      } else {
        fprintf(stderr, "rec_flip: byte %ld of a %d-byte sample or mask %ld out of range\n", at, len, mask);
      }
      free(cdr);
    } else {
      fprintf(stderr, "rec_flip: no data sample %ld of %s\n", n, argv[2]);
    }
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
  return rc;
}
