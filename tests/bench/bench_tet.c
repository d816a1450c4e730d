/* SPDX-License-Identifier: Apache-2.0 */
/* bench_tet: tetrahedral mesh build time and quality per organ.
 *
 * For each .obj in ASSETS_DIR/meshes and, when given and present,
 * SHARED_DIR/data/organs, builds the tetrahedral mesh at the automatic size
 * (~8 cells across the smallest extent) and at 16 and 24 cells across, and
 * reports the median build time over several runs (one core, this build's
 * flags), nodes, tetrahedra, min/mean radius-ratio quality, tetrahedra volume
 * over the enclosed volume and the surface vertices embedded by their nearest
 * tetrahedron. A surface that cannot be filled (the open tissue patch) or a
 * size over the tetrahedron limit prints its message instead of figures.
 * Prints a table and optionally writes CSV.
 * usage: bench_tet ASSETS_DIR [SHARED_DIR] [--csv OUT.csv] [--quick] */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"
#include "mesh_import.h"
#include "tet_mesh.h"

static int is_obj(const struct dirent *d) {
  size_t n = strlen(d->d_name);
  return n > 4 && !strcmp(d->d_name + n - 4, ".obj");
}

static int by_name(const struct dirent **a, const struct dirent **b) { return strcmp((*a)->d_name, (*b)->d_name); }

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* One row: `runs` builds at `edge` (0: automatic), the median time. */
static void bench_one(const char *name, const mesh_t *m, double edge, const char *label, int runs, FILE *csv) {
  double t[16];
  tet_build_report_t r = {0};
  verr_t err = {{0}};
  for (int i = 0; i < runs; i++) {
    tet_mesh_t tm;
    tet_embedding_t e;
    if (tet_mesh_build(m, edge, &tm, &e, &r, &err)) {
      const char *msg = strncmp(err.msg, "tet_mesh_build: ", 16) ? err.msg : err.msg + 16;
      printf("%-18s %-8s %7zu  %.90s\n", name, label, m->nverts, msg);
      return;
    }
    t[i] = r.seconds;
    tet_mesh_free(&tm);
    tet_embedding_free(&e);
  }
  qsort(t, (size_t)runs, sizeof t[0], cmp_double);
  double med = t[runs / 2], ratio = r.volume / fabs(r.surface_volume);
  printf("%-18s %-8s %7zu %7zu %8zu %9.2f %7.3f %7.3f %8.4f %8zu\n", name, label, m->nverts, r.nodes, r.tets, 1e3 * med,
         r.min_quality, r.mean_quality, ratio, r.outside_vertices);
  if (csv)
    fprintf(csv, "%s,%s,%g,%zu,%zu,%zu,%.6f,%.4f,%.4f,%.5f,%zu\n", name, label, edge, m->nverts, r.nodes, r.tets, med,
            r.min_quality, r.mean_quality, ratio, r.outside_vertices);
}

/* Benchmarks every .obj of dir; returns -1 when dir cannot be read. */
static int bench_dir(const char *dir, int runs, int quick, FILE *csv) {
  struct dirent **list = NULL;
  int n = scandir(dir, &list, is_obj, by_name);
  if (n < 0) return -1;
  for (int i = 0; i < n; i++) {
    char path[4096 + 256];
    snprintf(path, sizeof path, "%s/%s", dir, list[i]->d_name);
    mesh_t m;
    verr_t err = {{0}};
    if (mesh_import(path, &m, &err)) {
      printf("%-18s %s\n", list[i]->d_name, err.msg);
    } else {
      double lo[3], hi[3];
      mesh_bounds(&m, lo, hi);
      double mine = fmin(hi[0] - lo[0], fmin(hi[1] - lo[1], hi[2] - lo[2]));
      bench_one(list[i]->d_name, &m, 0, "auto", runs, csv);
      if (!quick && mine > 0) {
        bench_one(list[i]->d_name, &m, mine / 16, "1/16", runs, csv);
        bench_one(list[i]->d_name, &m, mine / 24, "1/24", runs, csv);
      }
      mesh_free(&m);
    }
    free(list[i]);
  }
  free(list);
  return 0;
}

int main(int argc, char **argv) {
  const char *assets = NULL, *shared = NULL, *csv_path = NULL;
  int quick = 0;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      quick = 1;
    else if (!strcmp(argv[i], "--csv") && i + 1 < argc)
      csv_path = argv[++i];
    else if (!assets)
      assets = argv[i];
    else if (!shared)
      shared = argv[i];
    else {
      fprintf(stderr, "usage: bench_tet ASSETS_DIR [SHARED_DIR] [--csv OUT.csv] [--quick]\n");
      return 2;
    }
  }
  if (!assets) {
    fprintf(stderr, "usage: bench_tet ASSETS_DIR [SHARED_DIR] [--csv OUT.csv] [--quick]\n");
    return 2;
  }
  FILE *csv = csv_path ? fopen(csv_path, "w") : NULL;
  if (csv_path && !csv) {
    fprintf(stderr, "bench_tet: cannot write %s\n", csv_path);
    return 1;
  }
  if (csv)
    fprintf(csv, "organ,size,edge,vertices,nodes,tets,build_s_median,min_quality,mean_quality,volume_ratio,outside\n");
  int runs = quick ? 1 : 5;
  printf("tet_mesh_build: median of %d run%s; size = cells across the smallest extent\n", runs, runs > 1 ? "s" : "");
  printf("%-18s %-8s %7s %7s %8s %9s %7s %7s %8s %8s\n", "organ", "size", "verts", "nodes", "tets", "build_ms", "q_min",
         "q_mean", "vol_ratio", "outside");
  char dir[4096];
  snprintf(dir, sizeof dir, "%s/meshes", assets);
  if (bench_dir(dir, runs, quick, csv)) {
    fprintf(stderr, "bench_tet: cannot read %s\n", dir);
    if (csv) fclose(csv);
    return 1;
  }
  if (shared) {
    snprintf(dir, sizeof dir, "%s/data/organs", shared);
    if (bench_dir(dir, runs, quick, csv)) printf("(%s absent: third-party organs skipped)\n", dir);
  }
  if (csv) fclose(csv);
  return 0;
}
