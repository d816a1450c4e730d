/* SPDX-License-Identifier: Apache-2.0 */
/* An organ with its own tetrahedra (scene key `volume`, organ_geometry.c and
 * physics/model_volume.c): the kidney's fill written by the project's own
 * writer and read back gives the same model as the automatic fill (nodes,
 * tetrahedra, the force of the same press within 2 %) for xpbd and
 * mass_spring_tet; without `mesh` the surface is the boundary of the
 * tetrahedra and still pushes back; a surface that does not belong to its
 * volume and a damaged volume file are refused naming the organ, the file
 * and the line. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "runtime/scene_runtime.h"
#include "test_assets.h"
#include "test_runtime.h"
#include "test_tmpfile.h"
#include "tet_mesh.h"
#include "volume_mesh.h"

static runtime_t rt;
static scene_t sc;
static char vol_path[256];

static const char *scene_text(const char *organ_lines, const char *model) {
  static char buf[2048];
  snprintf(buf, sizeof buf,
           "scene: vol\nphysics: {dt: 0.001}\norgans:\n  - name: kidney\n%s    model: %s\n"
           "    material: {mass: 0.15, distance_compliance: 2.0e-3, volume_compliance: 1.0e-4, home_stiffness: 30}\n"
           "    solver: {substeps: 1, iterations: 8, tet_size: 0.01}\n"
           "tools:\n  - {name: probe, radius: 0.003, stiffness: 400, max_force: 4}\n",
           organ_lines, model);
  return buf;
}

/* Down onto the kidney's top and held: the peak force (N). */
static double press(void) {
  const double away[3] = {0.012, 0.004, 0.07}, down[3] = {0.012, 0.004, 0.027};
  double peak = 0;
  for (int i = 0; i < 300; i++) {
    double s = i < 200 ? i / 200.0 : 1.0, p[3];
    for (int k = 0; k < 3; k++) p[k] = away[k] + (down[k] - away[k]) * s;
    runtime_set_tool(&rt, 0, p, 4);
    runtime_step(&rt);
    rt.events.n = 0;
    const double *f = rt.tools[0].force;
    peak = fmax(peak, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
  }
  return peak;
}

static void same_as_automatic(const char *model) {
  char lines[512];
  if (!test_runtime_load(&rt, &sc, scene_text("    mesh: ../meshes/kidney.obj\n", model), NULL)) {
    CHECK(0);
    return;
  }
  size_t nodes = rt.organs[0].model->nnodes, tets = rt.organs[0].model->ntets;
  double f_auto = press();
  runtime_destroy(&rt);
  snprintf(lines, sizeof lines, "    mesh: ../meshes/kidney.obj\n    volume: %s\n", vol_path);
  if (!test_runtime_load(&rt, &sc, scene_text(lines, model), NULL)) {
    CHECK(0);
    return;
  }
  CHECK(rt.organs[0].model->nnodes == nodes && rt.organs[0].model->ntets == tets);
  double f_file = press();
  runtime_destroy(&rt);
  printf("  %s: automatic fill %.4f N, the same tetrahedra from a file %.4f N\n", model, f_auto, f_file);
  CHECK(f_auto > 0.3);
  CHECK(fabs(f_file - f_auto) <= 0.02 * f_auto);
}

static void boundary_surface(void) {
  char lines[512];
  snprintf(lines, sizeof lines, "    volume: %s\n", vol_path);
  if (!test_runtime_load(&rt, &sc, scene_text(lines, "pbd"), NULL)) {
    CHECK(0);
    return;
  }
  const model_t *m = rt.organs[0].model;
  mesh_t kid;
  CHECK(test_mesh_load("kidney.obj", &kid) == 0);
  CHECK(m->nsurf > 0 && m->nsurf < m->nnodes && m->nsurf != kid.nverts);
  mesh_free(&kid);
  double f = press();
  printf("  pbd on the boundary of its tetrahedra: %.4f N\n", f);
  CHECK(f > 0.3 && isfinite(f));
  runtime_destroy(&rt);
}

static void refusals(void) {
  char lines[512];
  verr_t e = {{0}};
  /* The kidney's tetrahedra under the spleen's surface. */
  snprintf(lines, sizeof lines, "    mesh: ../meshes/spleen.obj\n    volume: %s\n", vol_path);
  CHECK(!test_runtime_load(&rt, &sc, scene_text(lines, "xpbd"), &e));
  CHECK(strstr(e.msg, "kidney") && strstr(e.msg, "outside its tetrahedral mesh"));
  /* A file cut short names itself and its line. */
  const char *bad = test_write_tmp("organ_vol_bad.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n");
  char bad_path[256];
  snprintf(bad_path, sizeof bad_path, "%s", bad);
  snprintf(lines, sizeof lines, "    volume: %s\n", bad_path);
  CHECK(!test_runtime_load(&rt, &sc, scene_text(lines, "xpbd"), &e));
  CHECK(strstr(e.msg, "kidney") && strstr(e.msg, "organ_vol_bad.msh:7:"));
  unlink(bad_path);
  /* Surface models have no tetrahedra to take. */
  CHECK(!test_runtime_load(NULL, &sc, scene_text(lines, "mass_spring_surface"), &e));
  CHECK(strstr(e.msg, "volume") && strstr(e.msg, "mass_spring_tet, pbd and xpbd"));
}

int main(void) {
  mesh_t kid;
  tet_mesh_t t;
  verr_t err = {{0}};
  if (test_mesh_load("kidney.obj", &kid) || tet_mesh_build(&kid, 0.01, &t, NULL, NULL, &err)) {
    fprintf(stderr, "cannot fill the kidney: %s\n", err.msg);
    return 1;
  }
  mesh_free(&kid);
  snprintf(vol_path, sizeof vol_path, "%s", test_tmp_path("organ_vol_kidney.vtk"));
  CHECK(volume_export(&t, VOLUME_VTK, vol_path, &err) == 0);
  tet_mesh_free(&t);
  same_as_automatic("xpbd");
  same_as_automatic("mass_spring_tet");
  boundary_surface();
  refusals();
  unlink(vol_path);
  return check_report("test_organ_volume");
}
