/* SPDX-License-Identifier: Apache-2.0 */
/* vdds_config (common/dds/vdds_config.h): without CYCLONEDDS_URI the loopback
 * configuration is set (and an existing value is kept); security is told
 * from inline XML and from file:// elements of the list; the "nothing seen"
 * explanation is due once, only after VDDS_NOTHING_SEEN_S without a match,
 * and names the domain, partition, configuration and both causes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "dds/vdds_config.h"
#include "test_tmpfile.h"

static const char *explain(char *buf, size_t cap) {
  FILE *f = fmemopen(buf, cap, "w");
  if (!f) return "";
  vdds_explain_nothing_seen(f, "tag", "no server here", 42, "lab/seat07", 5.0);
  fclose(f);
  return buf;
}

int main(void) {
  unsetenv("CYCLONEDDS_URI");
  CHECK(vdds_config_default() == 0);
  const char *u = getenv("CYCLONEDDS_URI");
  CHECK(u && strncmp(u, "file://", 7) == 0 && strstr(u, "deploy/cyclonedds-loopback.xml"));
  CHECK(vdds_config_secure() == 0);
  setenv("CYCLONEDDS_URI", "file:///elsewhere.xml", 1);
  CHECK(vdds_config_default() == 0 && strcmp(getenv("CYCLONEDDS_URI"), "file:///elsewhere.xml") == 0);

  /* Security: inline, in a listed file, absent. */
  setenv("CYCLONEDDS_URI", "<CycloneDDS><Domain><Security><Authentication/></Security></Domain></CycloneDDS>", 1);
  CHECK(vdds_config_secure() == 1);
  const char *sec =
      test_write_tmp("security.xml", "<CycloneDDS><Domain><Security>...</Security></Domain></CycloneDDS>");
  const char *plain = test_write_tmp("plain.xml", "<CycloneDDS><Domain><General/></Domain></CycloneDDS>");
  char uri[2048];
  snprintf(uri, sizeof uri, "file://%s, file://%s", plain, sec);
  setenv("CYCLONEDDS_URI", uri, 1);
  CHECK(vdds_config_secure() == 1);
  snprintf(uri, sizeof uri, "file://%s,file:///no/such/file.xml", plain);
  setenv("CYCLONEDDS_URI", uri, 1);
  CHECK(vdds_config_secure() == 0);

  /* Due once, after the delay, never with a match. */
  int told = 0;
  const uint64_t s = 1000000000ull, t0 = 10 * s;
  CHECK(vdds_nothing_seen_due(&told, 0, t0, t0 + 4 * s) == 0);
  CHECK(vdds_nothing_seen_due(&told, 1, t0, t0 + 6 * s) == 0 && told == 0);
  CHECK(vdds_nothing_seen_due(&told, 0, t0, t0 + 6 * s) == 1 && told == 1);
  CHECK(vdds_nothing_seen_due(&told, 0, t0, t0 + 9 * s) == 0);

  char buf[4096] = "";
  const char *t = explain(buf, sizeof buf);
  CHECK(strstr(t, "tag: nothing seen after 5 s: no server here") != NULL);
  CHECK(strstr(t, "listening on domain 42, partition 'lab/seat07'") != NULL);
  CHECK(strstr(t, "configuration: file://") != NULL && strstr(t, "DDS Security off") != NULL);
  CHECK(strstr(t, "likely cause: no server runs") != NULL);
  CHECK(strstr(t, "refuse a participant without identity") != NULL);
  snprintf(uri, sizeof uri, "file://%s,file://%s", plain, sec);
  setenv("CYCLONEDDS_URI", uri, 1);
  t = explain(buf, sizeof buf);
  CHECK(strstr(t, "DDS Security on") != NULL && strstr(t, "do not accept this identity") != NULL);
  unlink(sec);
  unlink(plain);
  /* Off loopback and not secure: refused, naming the file and the way on
   * (issue 14 item 5); loopback, secure or unset: allowed silently;
   * VISCERA_INSECURE=1 (what --insecure sets): allowed with a warning. */
  {
    char out[1024] = "";
    FILE *f;
    int warned = 0;
    verr_t e = {{0}};
    unsetenv("VISCERA_INSECURE");
    setenv("CYCLONEDDS_URI", "file:///opt/viscera/deploy/cyclonedds-loopback.xml", 1);
    CHECK(vdds_config_loopback() == 1);
    CHECK(vdds_config_check_insecure(stderr, "t", NULL, &e) == 0);
    /* A file that exists: one that does not is refused for that (below). */
    const char *src = getenv("VISCERA_SOURCE_DIR");
    char lan[1024], two[2048];
    snprintf(lan, sizeof lan, "file://%s/deploy/cyclonedds-lan.xml", src ? src : ".");
    setenv("CYCLONEDDS_URI", lan, 1);
    CHECK(vdds_config_loopback() == 0);
    f = fmemopen(out, sizeof out, "w");
    CHECK(f && vdds_config_check_insecure(f, "t", &warned, &e) == -1 && warned == 0);
    if (f) fclose(f);
    CHECK(out[0] == 0); /* refused: the message is the caller's to print */
    CHECK(strstr(e.msg, "refusing to start") && strstr(e.msg, "DDS Security is off") && strstr(e.msg, lan) &&
          strstr(e.msg, "--insecure") && strstr(e.msg, "VISCERA_INSECURE=1") && strstr(e.msg, "deploy/pki.sh"));
    CHECK(vdds_config_prepare(stderr, "t", &e) == -1); /* the path every participant takes */
    setenv("VISCERA_INSECURE", "0", 1);
    CHECK(vdds_config_check_insecure(stderr, "t", NULL, &e) == -1);
    setenv("VISCERA_INSECURE", "1", 1);
    f = fmemopen(out, sizeof out, "w");
    CHECK(f && vdds_config_check_insecure(f, "t", &warned, &e) == 0 && warned == 1);
    if (f) fclose(f);
    CHECK(strstr(out, "t: WARNING: insecure") && strstr(out, "cyclonedds-lan.xml"));
    out[0] = 0;
    f = fmemopen(out, sizeof out, "w");
    CHECK(f && vdds_config_check_insecure(f, "t", &warned, &e) == 0); /* warned once */
    if (f) fclose(f);
    CHECK(out[0] == 0);
    unsetenv("VISCERA_INSECURE");
    /* The identity's fragment named but not there (lab.sh's printed commands
     * with a relative --pki, pasted in another directory): the refusal names
     * that file, not "add an identity". */
    snprintf(two, sizeof two, "%s,file://no/such/pki/identities/instructor/security.xml", lan);
    setenv("CYCLONEDDS_URI", two, 1);
    CHECK(vdds_config_check_insecure(stderr, "t", NULL, &e) == -1);
    CHECK(strstr(e.msg, "file://no/such/pki/identities/instructor/security.xml, which cannot be read") &&
          strstr(e.msg, "relative path is read from the current directory /") && !strstr(e.msg, "Add an identity"));
    snprintf(two, sizeof two, "%s,file:///no/such/security.xml", lan);
    setenv("CYCLONEDDS_URI", two, 1);
    CHECK(vdds_config_check_insecure(stderr, "t", NULL, &e) == -1);
    CHECK(strstr(e.msg, "file:///no/such/security.xml, which cannot be read") && !strstr(e.msg, "relative path"));
    setenv("CYCLONEDDS_URI", "file:///x/cyclonedds-loopback.xml,<CycloneDDS><Domain><Security/></Domain></CycloneDDS>",
           1);
    CHECK(vdds_config_loopback() == 0 && vdds_config_check_insecure(stderr, "t", NULL, &e) == 0);
  }
  return check_report("test_vdds_config");
}
