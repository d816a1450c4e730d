/* SPDX-License-Identifier: Apache-2.0 */
#include "dds/vdds_ident.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "dds/vdds_config.h"
#include "dds/vdds_subject.h"

static char g_role[VDDS_ROLE_MAX] = "unknown";
static int g_tool = -1;
static char g_station[VDDS_ROLE_MAX] = "";

void vdds_set_role(const char *role) {
  if (!role || !*role) role = "unknown";
  size_t i = 0;
  for (; role[i] && i + 1 < sizeof g_role; i++) {
    unsigned char c = (unsigned char)role[i];
    /* one token: a space or '=' would make the announcement ambiguous */
    g_role[i] = (c > 0x20 && c < 0x7f && c != '=') ? (char)c : '_';
  }
  g_role[i] = 0;
}

void vdds_set_tool(int tool) { g_tool = tool < 0 ? -1 : tool; }

const char *vdds_role(void) { return g_role; }

void vdds_set_station(const char *station) {
  size_t i = 0;
  for (; station && station[i] && i + 1 < sizeof g_station; i++) {
    unsigned char c = (unsigned char)station[i];
    g_station[i] = (c > 0x20 && c < 0x7f && c != '=') ? (char)c : '_';
  }
  g_station[i] = 0;
}

size_t vdds_ident_format(char *out, size_t cap, const char *role, int tool, const char *host, long pid) {
  if (!cap) return 0;
  char tool_s[24] = "";
  if (tool >= 0) snprintf(tool_s, sizeof tool_s, "tool=%d ", tool);
  char raw[VDDS_IDENT_MAX * 2];
  snprintf(raw, sizeof raw, "viscera role=%s %shost=%s pid=%ld", role && *role ? role : "unknown", tool_s,
           host && *host ? host : "?", pid);
  /* the hostname is not ours to trust either: keep the text printable */
  return vdds_ident_sanitize(out, cap, raw, strlen(raw));
}

size_t vdds_ident_self(char *out, size_t cap) {
  char host[128] = "";
  if (gethostname(host, sizeof host - 1) != 0) host[0] = 0;
  host[sizeof host - 1] = 0;
  size_t n = vdds_ident_format(out, cap, g_role, g_tool, host, (long)getpid());
  /* The station last, so readers that know the fields above are unchanged. */
  if (g_station[0] && n < cap) {
    int k = snprintf(out + n, cap - n, " station=%s", g_station);
    if (k > 0) n = n + (size_t)k < cap ? n + (size_t)k : cap - 1;
  }
  /* Under DDS Security, the certificate's subject (DER, hex) that a secure
   * reader checks against this participant's GUID (vdds_subject.h). Only
   * whole: a cut token would not verify anyway. */
  uint8_t der[VDDS_SUBJECT_DER_MAX];
  size_t dn = vdds_config_secure() ? vdds_subject_self(der) : 0;
  if (dn && n + 6 + 2 * dn < cap) {
    n += (size_t)snprintf(out + n, cap - n, " cert=");
    for (size_t i = 0; i < dn; i++) n += (size_t)snprintf(out + n, cap - n, "%02x", der[i]);
  }
  return n;
}

dds_qos_t *vdds_participant_qos(void) {
  dds_qos_t *q = dds_create_qos();
  if (!q) return NULL;
  char id[VDDS_IDENT_MAX];
  size_t n = vdds_ident_self(id, sizeof id);
  dds_qset_userdata(q, id, n);
  return q;
}

size_t vdds_ident_sanitize(char *out, size_t cap, const void *in, size_t len) {
  if (!cap) return 0;
  const unsigned char *p = in;
  size_t n = 0;
  for (size_t i = 0; p && i < len && n + 1 < cap; i++) {
    if (p[i] == 0) break;
    out[n++] = (p[i] >= 0x20 && p[i] <= 0x7e) ? (char)p[i] : '?';
  }
  out[n] = 0;
  return n;
}

int vdds_ident_role(const char *ident, char *out, size_t cap) {
  if (cap) out[0] = 0;
  if (!ident || strncmp(ident, "viscera ", 8) != 0 || !cap) return -1;
  const char *p = ident + 7;
  /* the token must start after a space, so "xrole=" does not count */
  const char *r = strstr(p, " role=");
  if (!r) return -1;
  r += 6;
  size_t n = strcspn(r, " ");
  if (n == 0) return -1;
  if (n >= cap) n = cap - 1;
  memcpy(out, r, n);
  out[n] = 0;
  return 0;
}
