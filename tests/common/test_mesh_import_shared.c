/* SPDX-License-Identifier: Apache-2.0 */
/* The third-party organ meshes in ../shared/data/organs (real, imperfect
 * files): each imports, keeps every triangle of the file and prints its report.
 * Skips (77) when the shared folder is not there. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "mesh.h"
#include "mesh_check.h"
#include "mesh_import.h"

/* Counts the file's own "v " and "f " lines, independently of assimp. */
static void count_lines(const char *path, size_t *v, size_t *f) {
  *v = *f = 0;
  FILE *fp = fopen(path, "r");
  if (!fp) return;
  char line[1024];
  int at_start = 1;
  while (fgets(line, sizeof line, fp)) {
    if (at_start) {
      *v += line[0] == 'v' && line[1] == ' ';
      *f += line[0] == 'f' && line[1] == ' ';
    }
    at_start = strchr(line, '\n') != NULL;
  }
  fclose(fp);
}

/* Faces of more than three corners would add triangles; these files have none. */
static int has_only_triangles(const char *path) {
  FILE *fp = fopen(path, "r");
  if (!fp) return 0;
  char line[1024];
  int ok = 1;
  while (ok && fgets(line, sizeof line, fp)) {
    if (line[0] != 'f' || line[1] != ' ') continue;
    int corners = 0;
    for (char *tok = strtok(line + 2, " \t\r\n"); tok; tok = strtok(NULL, " \t\r\n")) corners++;
    ok = corners == 3;
  }
  fclose(fp);
  return ok;
}

static int by_name(const struct dirent **a, const struct dirent **b) { return strcmp((*a)->d_name, (*b)->d_name); }

static int is_obj(const struct dirent *e) {
  size_t n = strlen(e->d_name);
  return n > 4 && !strcmp(e->d_name + n - 4, ".obj");
}

int main(void) {
  const char *shared = getenv("VISCERA_SHARED_DIR");
  char dir[4096];
  snprintf(dir, sizeof dir, "%s/data/organs", shared ? shared : "");
  struct dirent **list = NULL;
  int n = shared ? scandir(dir, &list, is_obj, by_name) : -1;
  if (n <= 0) {
    printf("test_mesh_shared: skipped, no organ meshes in %s\n", shared ? dir : "(VISCERA_SHARED_DIR unset)");
    free(list);
    return 77;
  }
  for (int i = 0; i < n; i++) {
    char path[8192];
    snprintf(path, sizeof path, "%s/%s", dir, list[i]->d_name);
    free(list[i]);
    size_t vlines, flines;
    count_lines(path, &vlines, &flines);
    mesh_t m;
    verr_t err = {{0}};
    int rc = mesh_import(path, &m, &err);
    CHECK(rc == 0);
    if (rc) {
      fprintf(stderr, "%s\n", err.msg);
      continue;
    }
    mesh_report_t r;
    CHECK(mesh_check(&m, &r) == 0);
    printf("%s (%zu v lines, %zu f lines):\n", path, vlines, flines);
    mesh_report_print(&r, stdout);
    /* Welding only merges, and nothing that is a triangle may be lost. */
    CHECK(m.nverts > 0 && m.nverts <= vlines);
    if (has_only_triangles(path)) CHECK(m.ntris == flines);
    CHECK(r.duplicate_vertices == 0 && r.nonfinite_vertices == 0 && r.bad_index_faces == 0);
    mesh_free(&m);
  }
  free(list);
  return check_report("test_mesh_import_shared");
}
