/* SPDX-License-Identifier: Apache-2.0 */
#include "mesh_import.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* No aiProcess_JoinIdenticalVertices: it merges NaN vertices into finite ones
 * (seen with assimp 5.2), and the exact weld below does that job anyway. */
#define IMPORT_FLAGS (aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure)

mesh_import_opts_t mesh_import_default_opts(void) {
  mesh_import_opts_t o = {MESH_IMPORT_DEFAULT_MAX_FILE_BYTES, MESH_IMPORT_DEFAULT_MAX_TRIANGLES};
  return o;
}

int mesh_import(const char *path, mesh_t *out, verr_t *err) { return mesh_import_ex(path, NULL, out, err); }

/* Fails early with the OS's reason, which is clearer than assimp's guesses. */
static int check_file(const char *path, const mesh_import_opts_t *o, verr_t *err) {
  struct stat st;
  if (stat(path, &st) != 0) return verr_set(err, "%s: cannot open: %s", path, strerror(errno));
  if (!S_ISREG(st.st_mode)) return verr_set(err, "%s: not a regular file", path);
  if (st.st_size == 0) return verr_set(err, "%s: file is empty", path);
  if ((unsigned long long)st.st_size > (unsigned long long)o->max_file_bytes)
    return verr_set(err, "%s: file too large: %lld bytes (limit %zu)", path, (long long)st.st_size, o->max_file_bytes);
  FILE *f = fopen(path, "rb");
  if (!f) return verr_set(err, "%s: cannot open: %s", path, strerror(errno));
  fclose(f);
  return 0;
}

/* -0.0 and +0.0 are the same point; everything else welds on exact bits. */
static void pos_key(const double *p, uint64_t k[3]) {
  for (int i = 0; i < 3; i++) {
    double x = p[i] == 0.0 ? 0.0 : p[i];
    memcpy(&k[i], &x, sizeof x);
  }
}

static uint64_t mix64(uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return h;
}

/* canon[i] = the first vertex with the same position as vertex i. */
static int weld_map(const double *pos, size_t nv, uint32_t *canon, const char *path, verr_t *err) {
  size_t cap = 16;
  while (cap < 2 * nv) cap *= 2;
  uint32_t *slot = malloc(cap * sizeof *slot);
  if (!slot) return verr_set(err, "%s: out of memory welding %zu vertices", path, nv);
  memset(slot, 0xff, cap * sizeof *slot);
  for (size_t i = 0; i < nv; i++) {
    uint64_t k[3];
    pos_key(pos + 3 * i, k);
    size_t h = (size_t)mix64(k[0] ^ mix64(k[1] ^ mix64(k[2]))) & (cap - 1);
    for (;;) {
      uint32_t s = slot[h];
      if (s == UINT32_MAX) {
        slot[h] = (uint32_t)i;
        canon[i] = (uint32_t)i;
        break;
      }
      uint64_t ks[3];
      pos_key(pos + 3 * (size_t)s, ks);
      if (ks[0] == k[0] && ks[1] == k[1] && ks[2] == k[2]) {
        canon[i] = s;
        break;
      }
      h = (h + 1) & (cap - 1);
    }
  }
  free(slot);
  return 0;
}

/* Welds, drops unreferenced vertices and numbers the rest by first use. */
static int weld(const double *pos, size_t nv, const uint32_t *tris, size_t nt, mesh_t *out, const char *path,
                verr_t *err) {
  uint32_t *canon = malloc((nv + 1) * sizeof *canon);
  uint32_t *newid = malloc((nv + 1) * sizeof *newid);
  int rc = -1;
  if (!canon || !newid) {
    verr_set(err, "%s: out of memory welding %zu vertices", path, nv);
    goto done;
  }
  if (weld_map(pos, nv, canon, path, err)) goto done;
  memset(newid, 0xff, nv * sizeof *newid);
  uint32_t n = 0;
  for (size_t c = 0; c < 3 * nt; c++) {
    uint32_t r = canon[tris[c]];
    if (newid[r] == UINT32_MAX) newid[r] = n++;
  }
  if (mesh_alloc(out, n, nt, err)) {
    verr_set(err, "%s: out of memory for %u vertices, %zu triangles", path, n, nt);
    goto done;
  }
  for (size_t v = 0; v < nv; v++)
    if (canon[v] == v && newid[v] != UINT32_MAX)
      memcpy(out->pos + 3 * (size_t)newid[v], pos + 3 * v, 3 * sizeof(double));
  for (size_t c = 0; c < 3 * nt; c++) out->tris[c] = newid[canon[tris[c]]];
  rc = 0;
done:
  free(canon);
  free(newid);
  return rc;
}

/* Merges every mesh of the scene into flat arrays, checking sizes and values. */
static int flatten(const struct aiScene *s, const mesh_import_opts_t *o, const char *path, double **pos_out,
                   size_t *nv_out, uint32_t **tris_out, size_t *nt_out, verr_t *err) {
  size_t nv = 0, nt = 0;
  for (unsigned m = 0; m < s->mNumMeshes; m++) {
    const struct aiMesh *me = s->mMeshes[m];
    nv += me->mNumVertices;
    for (unsigned f = 0; f < me->mNumFaces; f++) nt += me->mFaces[f].mNumIndices == 3;
    if (nt > o->max_triangles)
      return verr_set(err, "%s: too large: more than %zu triangles (limit %zu)", path, nt, o->max_triangles);
    /* Three corners per triangle bound any useful vertex count; uint32 indices bound the rest. */
    if (nv > UINT32_MAX - 1 || nv > 3 * o->max_triangles + 3)
      return verr_set(err, "%s: too large: more than %zu vertices (limit %zu)", path, nv, 3 * o->max_triangles);
  }
  if (nt == 0) return verr_set(err, "%s: no triangles (the file holds only points or lines)", path);
  double *pos = malloc((3 * nv + 1) * sizeof *pos);
  uint32_t *tris = malloc((3 * nt + 1) * sizeof *tris);
  if (!pos || !tris) {
    free(pos);
    free(tris);
    return verr_set(err, "%s: out of memory for %zu vertices, %zu triangles", path, nv, nt);
  }
  size_t base = 0, t = 0;
  for (unsigned m = 0; m < s->mNumMeshes; m++) {
    const struct aiMesh *me = s->mMeshes[m];
    for (unsigned v = 0; v < me->mNumVertices; v++) {
      double p[3] = {me->mVertices[v].x, me->mVertices[v].y, me->mVertices[v].z};
      if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
        verr_set(err, "%s: mesh %u, vertex %u (importer's numbering) has a non-finite coordinate (%g, %g, %g)", path, m,
                 v, p[0], p[1], p[2]);
        free(pos);
        free(tris);
        return -1;
      }
      memcpy(pos + 3 * (base + v), p, sizeof p);
    }
    for (unsigned f = 0; f < me->mNumFaces; f++) {
      const struct aiFace *fa = &me->mFaces[f];
      if (fa->mNumIndices != 3) continue;
      for (int k = 0; k < 3; k++) {
        if (fa->mIndices[k] >= me->mNumVertices) {
          verr_set(err, "%s: face %u of mesh %u references vertex %u of %u", path, f, m, fa->mIndices[k],
                   me->mNumVertices);
          free(pos);
          free(tris);
          return -1;
        }
        tris[3 * t + k] = (uint32_t)(base + fa->mIndices[k]);
      }
      t++;
    }
    base += me->mNumVertices;
  }
  *pos_out = pos;
  *tris_out = tris;
  *nv_out = nv;
  *nt_out = nt;
  return 0;
}

int mesh_import_ex(const char *path, const mesh_import_opts_t *opts, mesh_t *out, verr_t *err) {
  mesh_import_opts_t o = opts ? *opts : mesh_import_default_opts();
  memset(out, 0, sizeof *out);
  if (check_file(path, &o, err)) return -1;
  const struct aiScene *s = aiImportFile(path, IMPORT_FLAGS);
  if (!s) return verr_set(err, "%s: cannot import: %s", path, aiGetErrorString());
  if (s->mNumMeshes == 0) {
    aiReleaseImport(s);
    return verr_set(err, "%s: no meshes in the file", path);
  }
  double *pos = NULL;
  uint32_t *tris = NULL;
  size_t nv = 0, nt = 0;
  int rc = flatten(s, &o, path, &pos, &nv, &tris, &nt, err);
  aiReleaseImport(s);
  if (rc) return -1;
  rc = weld(pos, nv, tris, nt, out, path, err);
  free(pos);
  free(tris);
  if (rc) return -1;
  if (mesh_validate(out, path, err)) {
    mesh_free(out);
    return -1;
  }
  return 0;
}
