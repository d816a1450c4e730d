/* SPDX-License-Identifier: Apache-2.0 */
#include "dds/vdds_config.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "data_path.h"

int vdds_config_default(void) {
  const char *uri = getenv("CYCLONEDDS_URI");
  if (uri && *uri) return 0;
  char path[DATA_PATH_MAX], value[DATA_PATH_MAX + 16];
  if (data_path_find(VDDS_LOOPBACK_CONFIG, path, sizeof path)) return -1;
  snprintf(value, sizeof value, "file://%s", path);
  return setenv("CYCLONEDDS_URI", value, 1) ? -1 : 0;
}

/* 1 when the text configures security. */
static int text_secure(const char *t) { return strstr(t, "<Security") || strstr(t, "<DDSSecurity"); }

/* 1 when the file at `path` configures security (first 64 kB read). */
static int file_secure(const char *path) {
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  static const size_t cap = 65536;
  char *buf = malloc(cap + 1);
  int secure = 0;
  if (buf) {
    size_t n = fread(buf, 1, cap, f);
    buf[n] = 0;
    secure = text_secure(buf);
    free(buf);
  }
  fclose(f);
  return secure;
}

/* Calls fn on each element of CYCLONEDDS_URI (Cyclone takes a
 * comma-separated list of file:// URIs and inline XML), trimmed of blanks at
 * both ends, until fn returns nonzero: that value, 0 when none did, -1 when
 * CYCLONEDDS_URI is unset or the copy cannot be made. */
static int uri_find(int (*fn)(const char *e, void *ctx), void *ctx) {
  const char *uri = getenv("CYCLONEDDS_URI");
  char *copy = uri ? strdup(uri) : NULL;
  if (!copy) return -1;
  int hit = 0;
  char *save = NULL;
  for (char *e = strtok_r(copy, ",", &save); e && !hit; e = strtok_r(NULL, ",", &save)) {
    while (*e == ' ' || *e == '\t' || *e == '\n') e++;
    size_t n = strlen(e);
    while (n && (e[n - 1] == ' ' || e[n - 1] == '\t' || e[n - 1] == '\n')) e[--n] = 0;
    hit = fn(e, ctx);
  }
  free(copy);
  return hit;
}

static int elem_secure(const char *e, void *ctx) {
  (void)ctx;
  return strncmp(e, "file://", 7) == 0 ? file_secure(e + 7) : text_secure(e);
}

int vdds_config_secure(void) {
  const char *uri = getenv("CYCLONEDDS_URI");
  return uri && *uri && uri_find(elem_secure, NULL) > 0;
}

static int elem_not_loopback(const char *e, void *ctx) {
  (void)ctx;
  static const char want[] = "/cyclonedds-loopback.xml";
  size_t n = strlen(e);
  return !(strncmp(e, "file://", 7) == 0 && n >= sizeof want - 1 && !strcmp(e + n - (sizeof want - 1), want));
}

int vdds_config_loopback(void) {
  const char *uri = getenv("CYCLONEDDS_URI");
  if (!uri || !*uri) return 1;
  return uri_find(elem_not_loopback, NULL) == 0; /* every element the loopback file */
}

typedef struct unreadable {
  char *path;
  size_t cap;
  int why;
} unreadable_t;

static int elem_unreadable(const char *e, void *ctx) {
  unreadable_t *u = ctx;
  if (strncmp(e, "file://", 7) != 0) return 0;
  FILE *t = fopen(e + 7, "r");
  if (t) {
    fclose(t);
    return 0;
  }
  u->why = errno;
  snprintf(u->path, u->cap, "%s", e + 7);
  return 1;
}

/* The first file:// element of CYCLONEDDS_URI that cannot be opened, copied
 * into `path` with the reason in *why; 0 when there is none. A security
 * fragment that is not there reads as "security off", and the refusal would
 * then tell the user to add the identity they did name. */
static int unreadable_file(char *path, size_t cap, int *why) {
  unreadable_t u = {.path = path, .cap = cap, .why = 0};
  if (uri_find(elem_unreadable, &u) <= 0) return 0;
  *why = u.why;
  return 1;
}

int vdds_config_check_insecure(FILE *f, const char *tag, int *warned, verr_t *err) {
  if (vdds_config_loopback() || vdds_config_secure()) return 0;
  const char *uri = getenv("CYCLONEDDS_URI");
  const char *ins = getenv("VISCERA_INSECURE");
  if (!ins || strcmp(ins, "1")) {
    /* A file that is not there (a security fragment named by a relative
     * path, pasted in another directory) reads as "security off": name it
     * instead of telling the user to add the identity they did name. */
    char missing[256], cwd[128];
    int why = 0;
    if (unreadable_file(missing, sizeof missing, &why)) {
      int rel = missing[0] != '/';
      if (!rel || !getcwd(cwd, sizeof cwd)) cwd[0] = 0;
      verr_set(err,
               "refusing to start: CYCLONEDDS_URI names file://%s, which cannot be read (%s%s%s); name it by its "
               "absolute path (file:///...)",
               missing, strerror(why), rel ? "; a relative path is read from the current directory " : "", cwd);
      return -1;
    }
    verr_set(err,
             "refusing to start: DDS Security is off and CYCLONEDDS_URI (%s) is not the loopback configuration: "
             "anyone on that network could read this session and drive its tools. Add an identity from "
             "deploy/pki.sh to it (deploy/lab.sh --secure), or pass --insecure (or set VISCERA_INSECURE=1) to run "
             "without DDS Security",
             uri);
    return -1;
  }
  if (!warned || !*warned)
    fprintf(f,
            "%s: WARNING: insecure (--insecure or VISCERA_INSECURE=1): DDS Security is off on %s; anyone on that "
            "network can read this session and drive its tools\n",
            tag, uri);
  if (warned) *warned = 1;
  return 0;
}

int vdds_config_prepare(FILE *f, const char *tag, verr_t *err) {
  vdds_config_default(); /* no CYCLONEDDS_URI: the loopback configuration, like the scripts */
  return vdds_config_check_insecure(f, tag, NULL, err);
}

int vdds_matched_writers(dds_entity_t reader) {
  dds_subscription_matched_status_t st;
  return dds_get_subscription_matched_status(reader, &st) == DDS_RETCODE_OK ? (int)st.current_count : 0;
}

int vdds_matched_readers(dds_entity_t writer) {
  dds_publication_matched_status_t st;
  return dds_get_publication_matched_status(writer, &st) == DDS_RETCODE_OK ? (int)st.current_count : 0;
}

int vdds_nothing_seen_due(int *reported, int matched, uint64_t start_ns, uint64_t now_ns) {
  if (*reported || matched > 0 || now_ns < start_ns || (double)(now_ns - start_ns) < VDDS_NOTHING_SEEN_S * 1e9)
    return 0;
  *reported = 1;
  return 1;
}

void vdds_explain_nothing_seen(FILE *f, const char *tag, const char *what, int domain, const char *partition,
                               double waited_s) {
  const char *uri = getenv("CYCLONEDDS_URI");
  int secure = vdds_config_secure();
  fprintf(f, "%s: nothing seen after %.0f s: %s\n", tag, waited_s, what);
  fprintf(f, "%s:   listening on domain %d, partition '%s'\n", tag, domain, partition ? partition : "");
  fprintf(f, "%s:   configuration: %s, DDS Security %s\n", tag, uri && *uri ? uri : "(Cyclone DDS defaults)",
          secure ? "on" : "off");
  fprintf(f,
          "%s:   likely cause: no server runs on this domain and partition (start it, or check --domain / "
          "$VISCERA_DOMAIN and --partition against the server's)\n",
          tag);
  if (secure)
    fprintf(f,
            "%s:   or: the peers do not accept this identity (another PKI, or permissions that do not cover "
            "this domain and partition)\n",
            tag);
  else
    fprintf(f,
            "%s:   or: the peers run with DDS Security and refuse a participant without identity (add your "
            "identity: CYCLONEDDS_URI=\"file://.../cyclonedds-loopback.xml,file://PKI/identities/NAME/"
            "security.xml\")\n",
            tag);
}
