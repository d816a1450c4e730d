/* SPDX-License-Identifier: Apache-2.0 */
/* data_path (common/data_path.h): $VISCERA_DATA_DIR comes first; a relative
 * name is found under ROOT/subdir (also by its base name); a path that
 * exists as given is used as given; a name found nowhere is handed back
 * unchanged with -1 (so the caller's error names what the user typed); the
 * source tree (the last root) holds the loopback configuration. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "data_path.h"
#include "test_tmpfile.h"

int main(void) {
  char out[DATA_PATH_MAX], root[512], buf[DATA_PATH_MAX];
  /* A data root of our own with assets/scenes/x.yaml in it. */
  snprintf(root, sizeof root, "%s", test_tmp_path("data_root"));
  snprintf(buf, sizeof buf, "%s/assets", root);
  mkdir(root, 0755);
  mkdir(buf, 0755);
  snprintf(buf, sizeof buf, "%s/assets/scenes", root);
  mkdir(buf, 0755);
  snprintf(buf, sizeof buf, "%s/assets/scenes/only_here.yaml", root);
  FILE *f = fopen(buf, "w");
  CHECK(f != NULL);
  if (f) fclose(f);

  /* Without $VISCERA_DATA_DIR: the source tree has the configuration. */
  unsetenv("VISCERA_DATA_DIR");
  CHECK(data_path_root(0, out, sizeof out) == NULL);
  CHECK(data_path_find("deploy/cyclonedds-loopback.xml", out, sizeof out) == 0);
  CHECK(strstr(out, "deploy/cyclonedds-loopback.xml") != NULL);
  CHECK(data_path_find("assets/scenes/only_here.yaml", out, sizeof out) == -1 && out[0] == 0);
  /* A scene by name from the source tree, from any directory. */
  CHECK(chdir("/") == 0);
  CHECK(data_path_resolve("default.yaml", "assets/scenes", out, sizeof out) == 0);
  CHECK(strstr(out, "/assets/scenes/default.yaml") != NULL);
  /* By base name too. */
  CHECK(data_path_resolve("somewhere/default.yaml", "assets/scenes", out, sizeof out) == 0);
  /* Found nowhere: the name comes back as typed. */
  CHECK(data_path_resolve("no_such_scene.yaml", "assets/scenes", out, sizeof out) == -1);
  CHECK(strcmp(out, "no_such_scene.yaml") == 0);
  CHECK(data_path_resolve("/abs/missing.yaml", "assets/scenes", out, sizeof out) == -1);
  CHECK(strcmp(out, "/abs/missing.yaml") == 0);

  /* $VISCERA_DATA_DIR first. */
  setenv("VISCERA_DATA_DIR", root, 1);
  CHECK(data_path_root(0, out, sizeof out) && strcmp(out, root) == 0);
  CHECK(data_path_resolve("only_here.yaml", "assets/scenes", out, sizeof out) == 0);
  snprintf(buf, sizeof buf, "%s/assets/scenes/only_here.yaml", root);
  CHECK(strcmp(out, buf) == 0);
  /* A path that exists as given wins over every root. */
  CHECK(chdir(root) == 0);
  CHECK(data_path_resolve("assets/scenes/only_here.yaml", "assets/scenes", out, sizeof out) == 0);
  CHECK(strcmp(out, "assets/scenes/only_here.yaml") == 0);
  /* Too small an output: not found, never overflowed. */
  char tiny[8];
  CHECK(data_path_find("deploy/cyclonedds-loopback.xml", tiny, sizeof tiny) == -1);
  /* The binary's own ../share/viscera is a root (absent for a test binary). */
  CHECK(data_path_root(1, out, sizeof out) && strstr(out, "/../share/viscera") != NULL);
  snprintf(buf, sizeof buf, "%s/assets/scenes/only_here.yaml", root);
  unlink(buf);
  snprintf(buf, sizeof buf, "%s/assets/scenes", root);
  rmdir(buf);
  snprintf(buf, sizeof buf, "%s/assets", root);
  rmdir(buf);
  rmdir(root);
  return check_report("test_data_path");
}
