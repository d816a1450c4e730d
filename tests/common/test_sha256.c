/* SPDX-License-Identifier: Apache-2.0 */
/* sha256 (common/sha256.h): the FIPS 180-4 test vectors (empty, "abc",
 * the two-block 448-bit message, a million 'a' fed as a file across read
 * boundaries) and a missing file named in the error. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "sha256.h"

int main(void) {
  char hex[SHA256_HEX_LEN];
  sha256_hex("", 0, hex);
  CHECK(!strcmp(hex, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"));
  sha256_hex("abc", 3, hex);
  CHECK(!strcmp(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"));
  const char *m = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  sha256_hex(m, strlen(m), hex);
  CHECK(!strcmp(hex, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"));
  char path[] = "/tmp/test_sha256_XXXXXX";
  int fd = mkstemp(path);
  CHECK(fd >= 0);
  FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
  CHECK(f != NULL);
  if (f) {
    for (int i = 0; i < 1000000; i++) fputc('a', f);
    fclose(f);
  }
  uint64_t size = 0;
  verr_t err;
  CHECK(sha256_file(path, hex, &size, &err) == 0);
  CHECK(size == 1000000);
  CHECK(!strcmp(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0"));
  remove(path);
  CHECK(sha256_file(path, hex, &size, &err) == -1);
  CHECK(strstr(err.msg, path) != NULL);
  return check_report("test_sha256");
}
