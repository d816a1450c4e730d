/* SPDX-License-Identifier: Apache-2.0 */
/* vdds_subject (common/dds/vdds_subject.h): a subject's text is RFC 2253;
 * the GUID check accepts exactly the prefix DDS Security derives from the
 * subject (written here as one 48-bit number: a 1, then the hash's first 47
 * bits) and refuses any other bit; an announcement naming another subject,
 * malformed hex, or a DER that is no X.509 name is refused; none is none.
 * rec_subject (integration) checks the same against Cyclone's own GUIDs. */
#include <stdio.h>
#include <string.h>

#include <openssl/sha.h>
#include <openssl/x509.h>

#include "check.h"
#include "dds/vdds_subject.h"

static size_t name_der(const char *cn, uint8_t *out) {
  X509_NAME *n = X509_NAME_new();
  X509_NAME_add_entry_by_txt(n, "C", MBSTRING_ASC, (const unsigned char *)"NL", -1, -1, 0);
  X509_NAME_add_entry_by_txt(n, "O", MBSTRING_ASC, (const unsigned char *)"viscera", -1, -1, 0);
  X509_NAME_add_entry_by_txt(n, "CN", MBSTRING_ASC, (const unsigned char *)cn, -1, -1, 0);
  unsigned char *d = NULL;
  int len = i2d_X509_NAME(n, &d);
  memcpy(out, d, (size_t)len);
  OPENSSL_free(d);
  X509_NAME_free(n);
  return (size_t)len;
}

static void guid_for(const uint8_t *der, size_t len, uint8_t guid[16]) {
  unsigned char h[SHA256_DIGEST_LENGTH];
  SHA256(der, len, h);
  uint64_t h48 = 0;
  for (int i = 0; i < 6; i++) h48 = h48 << 8 | h[i];
  uint64_t p = (UINT64_C(1) << 47) | (h48 >> 1);
  for (int i = 0; i < 6; i++) guid[i] = (uint8_t)(p >> (8 * (5 - i)));
  for (int i = 6; i < 16; i++) guid[i] = (uint8_t)(0x11 * i); /* the rest is not the subject's */
}

static void ident_with(const uint8_t *der, size_t len, char *out, size_t cap) {
  size_t n = (size_t)snprintf(out, cap, "viscera role=haptic host=h pid=1 station=s cert=");
  for (size_t i = 0; i < len && n + 3 < cap; i++) n += (size_t)snprintf(out + n, cap - n, "%02x", der[i]);
}

int main(void) {
  uint8_t a[VDDS_SUBJECT_DER_MAX], b[VDDS_SUBJECT_DER_MAX], guid[16];
  size_t na = name_der("trainee-seat01", a), nb = name_der("trainee-seat02", b);
  char text[VDDS_SUBJECT_TEXT_MAX], ident[512];
  CHECK(vdds_subject_text(a, na, text, sizeof text) == 0);
  CHECK(strcmp(text, "CN=trainee-seat01,O=viscera,C=NL") == 0);
  CHECK(vdds_subject_text(a, na - 1, text, sizeof text) == -1); /* truncated DER */

  guid_for(a, na, guid);
  CHECK(vdds_subject_matches_guid(guid, a, na));
  CHECK(!vdds_subject_matches_guid(guid, b, nb));
  for (int bit = 0; bit < 48; bit++) {
    guid[bit / 8] ^= (uint8_t)(0x80 >> (bit % 8));
    CHECK(!vdds_subject_matches_guid(guid, a, na));
    guid[bit / 8] ^= (uint8_t)(0x80 >> (bit % 8));
  }

  ident_with(a, na, ident, sizeof ident);
  CHECK(vdds_subject_verify(ident, guid, text, sizeof text) == VDDS_SUBJECT_VERIFIED);
  CHECK(strcmp(text, "CN=trainee-seat01,O=viscera,C=NL") == 0);
  ident_with(b, nb, ident, sizeof ident); /* seat02's subject from seat01's participant */
  CHECK(vdds_subject_verify(ident, guid, text, sizeof text) == VDDS_SUBJECT_MISMATCH && text[0] == 0);
  CHECK(vdds_subject_verify("viscera role=haptic host=h pid=1 cert=3g", guid, text, sizeof text) ==
        VDDS_SUBJECT_MISMATCH);
  CHECK(vdds_subject_verify("viscera role=haptic host=h pid=1 cert=", guid, text, sizeof text) ==
        VDDS_SUBJECT_MISMATCH);
  CHECK(vdds_subject_verify("viscera role=haptic host=h pid=1", guid, text, sizeof text) == VDDS_SUBJECT_NONE);
  /* a GUID that matches bytes which are no X.509 name */
  const uint8_t junk[] = {0x30, 0x03, 0x01, 0x01, 0xff};
  guid_for(junk, sizeof junk, guid);
  CHECK(vdds_subject_verify("viscera role=x host=h pid=1 cert=30030101ff", guid, text, sizeof text) ==
        VDDS_SUBJECT_MISMATCH);
  /* longer than the bound */
  char big[2 * VDDS_SUBJECT_DER_MAX + 64] = "viscera role=x cert=";
  for (size_t i = strlen(big); i + 1 < sizeof big; i++) big[i] = 'a';
  CHECK(vdds_subject_verify(big, guid, text, sizeof text) == VDDS_SUBJECT_MISMATCH);
  return check_report("test_vdds_subject");
}
