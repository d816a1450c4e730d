/* SPDX-License-Identifier: Apache-2.0 */
/* fuzz_mesh: mutated mesh files (OBJ text) against the importer and the
 * organ mesh checks (fuzz_files.h; issue 15 items 3 and 5). Contracts:
 * mesh_import never crashes and what it returns passes mesh_validate;
 * mesh_admit (closed, and sheet) never crashes, refuses with a message
 * naming the file, and what it admits is one connected, manifold,
 * consistently wound surface without degenerate triangles, of a size in
 * range, closed and outward (positive volume) when a closed one was asked
 * for; admitting it again repairs nothing.
 * Corpus: the .obj files of tests/fuzz/corpus/mesh. */
#include <math.h>

#include "fuzz_files.h"
#include "mesh.h"
#include "mesh_admit.h"
#include "mesh_check.h"
#include "mesh_import.h"

static const char *const dict[] = {"v 1e30 0 0\n",
                                   "v 0 0 1e-30\n",
                                   "v nan 0 0\n",
                                   "v inf 1 1\n",
                                   "f 1 2 3\n",
                                   "f 1 1 1\n",
                                   "f 3 2 1\n",
                                   "f 0 0 0\n",
                                   "f -1 -2 -3\n",
                                   "f 1 2 999999\n",
                                   "f 1/1/1 2/2/2 3/3/3\n",
                                   "vn 0 0 1\n",
                                   "vt 0 0\n",
                                   "o part\n",
                                   "g g\n",
                                   "usemtl m\n",
                                   "l 1 2\n",
                                   "p 1\n",
                                   "#",
                                   "\n",
                                   " ",
                                   "1e308",
                                   "-",
                                   "f 1 2 3 4 5\n"};

static const char *check_admitted(const mesh_t *m, int closed) {
  mesh_report_t r;
  if (mesh_check(m, &r)) return NULL; /* out of memory: not a contract */
  if (r.degenerate_faces) return "admitted a mesh with degenerate triangles";
  if (r.nonmanifold_edges) return "admitted a non-manifold mesh";
  if (r.components != 1) return "admitted a mesh in several parts";
  if (r.inconsistent_edges) return "admitted an inconsistently wound mesh";
  if (closed && r.boundary_edges) return "admitted an open mesh as closed";
  if (!r.boundary_edges && !(r.volume > 0)) return "admitted a closed mesh that is not outward";
  double d[3] = {r.size[0], r.size[1], r.size[2]};
  double diag = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(diag >= MESH_ADMIT_MIN_SIZE && diag <= MESH_ADMIT_MAX_SIZE)) return "admitted a mesh of absurd size";
  return NULL;
}

static const char *run_mesh(const char *path, long *admitted) {
  mesh_t m = {0};
  verr_t e;
  if (mesh_import(path, &m, &e)) return strstr(e.msg, path) ? NULL : "an import refusal does not name the file";
  const char *why = NULL;
  if (mesh_validate(&m, path, &e)) why = "the importer returned an invalid mesh";
  for (int closed = 1; closed >= 0 && !why; closed--) {
    mesh_t c;
    if (mesh_copy(&c, &m, &e)) break;
    mesh_admit_opts_t o = {!closed, MESH_ADMIT_MIN_SIZE, MESH_ADMIT_MAX_SIZE};
    char note[200];
    if (mesh_admit(&c, &o, path, note, sizeof note, &e) == 0) {
      (*admitted)++;
      why = check_admitted(&c, closed);
      if (!why && (mesh_admit(&c, &o, path, note, sizeof note, &e) || note[0]))
        why = "a second admission repaired or refused the admitted mesh";
    } else if (strncmp(e.msg, path, strlen(path))) {
      why = "a refusal does not name the file";
    }
    mesh_free(&c);
  }
  mesh_free(&m);
  return why;
}

int main(int argc, char **argv) {
  fuzz_run_t r = {0};
  if (fuzz_args(&r, "fuzz_mesh", argc, argv)) return 2;
  fuzz_corpus_t c;
  if (fuzz_corpus_load(&c, r.corpus_dir, ".obj")) {
    fprintf(stderr, "fuzz_mesh: no .obj seeds in %s\n", r.corpus_dir);
    return 1;
  }
  int failed = 0;
  long admitted = 0, rounds = 0;
  double t0 = fuzz_now();
  fuzz_buf_t b = {0};
  for (long i = -(long)c.n; i < r.iterations; i++, rounds++) {
    if (fuzz_now() - t0 > r.cap_s) {
      printf("fuzz_mesh: safety stop after %ld rounds (%.0f s cap)\n", rounds, r.cap_s);
      break;
    }
    uint64_t s = r.seed * 0x9e3779b97f4a7c15ull + (uint64_t)i;
    size_t pick = i < 0 ? (size_t)(i + (long)c.n) : fuzz_below(&s, c.n);
    if (fuzz_buf_reserve(&b, c.data[pick].n + 1)) return 1;
    memcpy(b.p, c.data[pick].p, c.data[pick].n + 1);
    b.n = c.data[pick].n;
    if (i >= 0) fuzz_mutate(&b, &s, dict, sizeof dict / sizeof *dict);
    fuzz_pending(&r, i, ".obj", b.p, b.n);
    const char *why = run_mesh(r.pending, &admitted);
    if (why) {
      fuzz_failed(&r, i, why);
      failed++;
    } else {
      fuzz_passed(&r);
    }
  }
  printf("fuzz_mesh: %ld rounds from %zu seeds, %ld admissions, %d failed\n", rounds, c.n, admitted, failed);
  free(b.p);
  fuzz_corpus_free(&c);
  return failed ? 1 : 0;
}
