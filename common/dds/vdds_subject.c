/* SPDX-License-Identifier: Apache-2.0 */
#include "dds/vdds_subject.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <openssl/bio.h>
#include <openssl/pem.h>
#include <openssl/sha.h>
#include <openssl/x509.h>

#define CERT_TAG "<IdentityCertificate>"
#define CERT_END "</IdentityCertificate>"

/* The certificate named in one configuration text, as an X509; NULL if none. */
static X509 *cert_from_text(const char *t) {
  const char *a = strstr(t, CERT_TAG);
  if (!a) return NULL;
  a += strlen(CERT_TAG);
  while (*a == ' ' || *a == '\n' || *a == '\t' || *a == '\r') a++;
  const char *b = strstr(a, CERT_END);
  if (!b) return NULL;
  while (b > a && (b[-1] == ' ' || b[-1] == '\n' || b[-1] == '\t' || b[-1] == '\r')) b--;
  char *v = strndup(a, (size_t)(b - a));
  if (!v) return NULL;
  X509 *x = NULL;
  BIO *bio = NULL;
  if (strncmp(v, "data:,", 6) == 0) {
    bio = BIO_new_mem_buf(v + 6, -1);
  } else if (strncmp(v, "file:", 5) == 0) {
    const char *path = v + 5;
    if (strncmp(path, "//", 2) == 0) path += 2; /* file:///abs as well as file:/abs */
    bio = BIO_new_file(path, "r");
  }
  if (bio) x = PEM_read_bio_X509(bio, NULL, NULL, NULL);
  BIO_free(bio);
  free(v);
  return x;
}

static char *read_head(const char *path) {
  FILE *f = fopen(path, "r");
  if (!f) return NULL;
  static const size_t cap = 65536;
  char *buf = malloc(cap + 1);
  if (buf) buf[fread(buf, 1, cap, f)] = 0;
  fclose(f);
  return buf;
}

static X509 *cert_from_config(void) {
  const char *uri = getenv("CYCLONEDDS_URI");
  if (!uri || !*uri) return NULL;
  char *copy = strdup(uri);
  X509 *x = NULL;
  char *save = NULL;
  /* comma-separated file:// elements and inline XML, as vdds_config.c */
  for (char *e = copy ? strtok_r(copy, ",", &save) : NULL; e && !x; e = strtok_r(NULL, ",", &save)) {
    while (*e == ' ' || *e == '\t' || *e == '\n') e++;
    if (strncmp(e, "file://", 7) == 0) {
      char *t = read_head(e + 7);
      if (t) x = cert_from_text(t);
      free(t);
    } else {
      x = cert_from_text(e);
    }
  }
  free(copy);
  return x;
}

/* The identity's subject, read once per process: seats of one server run
 * as threads (server_app.h), and each opens its participant. */
static struct {
  uint8_t der[VDDS_SUBJECT_DER_MAX];
  size_t len;
} g_self;
static pthread_once_t g_self_once = PTHREAD_ONCE_INIT;

static void read_self(void) {
  X509 *x = cert_from_config();
  unsigned char *d = NULL;
  int n = x ? i2d_X509_NAME(X509_get_subject_name(x), &d) : -1;
  if (n > 0 && (size_t)n <= sizeof g_self.der) {
    memcpy(g_self.der, d, (size_t)n);
    g_self.len = (size_t)n;
  }
  OPENSSL_free(d);
  X509_free(x);
}

size_t vdds_subject_self(uint8_t der[VDDS_SUBJECT_DER_MAX]) {
  pthread_once(&g_self_once, read_self);
  memcpy(der, g_self.der, g_self.len);
  return g_self.len;
}

bool vdds_subject_matches_guid(const uint8_t guid[16], const uint8_t *der, size_t len) {
  unsigned char h[SHA256_DIGEST_LENGTH];
  SHA256(der, len, h);
  /* Cyclone's get_adjusted_participant_guid: a 1 bit, then 47 bits of the
   * subject's hash; the other 6 prefix bytes hash the candidate GUID. */
  uint8_t hb = 0x80;
  for (int i = 0; i < 6; i++) {
    if (guid[i] != (uint8_t)(hb | h[i] >> 1)) return false;
    hb = (uint8_t)(h[i] << 7);
  }
  return true;
}

int vdds_subject_text(const uint8_t *der, size_t len, char *out, size_t cap) {
  if (cap) out[0] = 0;
  const unsigned char *p = der;
  X509_NAME *name = d2i_X509_NAME(NULL, &p, (long)len);
  if (!name || p != der + len) {
    X509_NAME_free(name);
    return -1;
  }
  BIO *bio = BIO_new(BIO_s_mem());
  int ok = bio && X509_NAME_print_ex(bio, name, 0, XN_FLAG_RFC2253) >= 0;
  char *data = NULL;
  long n = ok ? BIO_get_mem_data(bio, &data) : 0;
  size_t k = 0;
  for (long i = 0; i < n && k + 1 < cap; i++) {
    unsigned char c = (unsigned char)data[i];
    out[k++] = (c >= 0x20 && c <= 0x7e) ? (char)c : '?';
  }
  if (cap) out[k] = 0;
  BIO_free(bio);
  X509_NAME_free(name);
  return ok && n > 0 ? 0 : -1;
}

static int hexval(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

int vdds_subject_verify(const char *ident, const uint8_t guid[16], char *out, size_t cap) {
  if (cap) out[0] = 0;
  const char *t = ident ? strstr(ident, " cert=") : NULL;
  if (!t) return VDDS_SUBJECT_NONE;
  t += 6;
  uint8_t der[VDDS_SUBJECT_DER_MAX];
  size_t n = 0;
  while (t[0] && t[0] != ' ') {
    int hi = hexval(t[0]), lo = hexval(t[1]);
    if (hi < 0 || lo < 0 || n == sizeof der) return VDDS_SUBJECT_MISMATCH;
    der[n++] = (uint8_t)(hi << 4 | lo);
    t += 2;
  }
  if (n == 0 || !vdds_subject_matches_guid(guid, der, n)) return VDDS_SUBJECT_MISMATCH;
  char text[VDDS_SUBJECT_TEXT_MAX];
  if (vdds_subject_text(der, n, text, sizeof text) < 0) return VDDS_SUBJECT_MISMATCH;
  snprintf(out, cap, "%s", text);
  return VDDS_SUBJECT_VERIFIED;
}
