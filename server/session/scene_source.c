/* SPDX-License-Identifier: Apache-2.0 */
#include "session/scene_source.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "build_id.h"
#include "cli.h"
#include "sha256.h"

/* As common/scene.c caps a scene file. */
#define SCENE_SOURCE_MAX_BYTES (1u << 20)

/* The whole file as a string (NULL when it cannot be read). */
static char *read_text(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  char *buf = malloc(SCENE_SOURCE_MAX_BYTES + 2);
  size_t n = buf ? fread(buf, 1, SCENE_SOURCE_MAX_BYTES + 1, f) : 0;
  int bad = ferror(f) || n > SCENE_SOURCE_MAX_BYTES;
  fclose(f);
  if (!buf || bad) {
    free(buf);
    return NULL;
  }
  buf[n] = 0;
  *len = n;
  return buf;
}

int scene_source_fill(viscera_SceneSource *out, const scene_t *sc, const char *station, verr_t *err) {
  memset(out, 0, sizeof *out);
  int rc = 0;
  snprintf(out->scene, sizeof out->scene, "%s", sc->name);
  char abs[PATH_MAX];
  snprintf(out->path, sizeof out->path, "%.1024s", realpath(sc->path, abs) ? abs : sc->path);
  size_t len = 0;
  out->text = read_text(sc->path, &len);
  if (!out->text) {
    rc = verr_set(err, "%s: cannot read the scene file to record it", sc->path);
    out->text = calloc(1, 1);
  } else {
    sha256_hex(out->text, len, out->text_sha256);
  }
  viscera_MeshHash *m = calloc(sc->norgans + 1, sizeof *m);
  for (size_t i = 0; m && i < sc->norgans; i++) {
    const char *p = realpath(sc->organs[i].mesh, abs) ? abs : sc->organs[i].mesh;
    snprintf(m[i].path, sizeof m[i].path, "%.1024s", p);
    uint64_t size = 0;
    verr_t e;
    if (sha256_file(p, m[i].sha256, &size, &e)) {
      if (!rc) rc = verr_set(err, "%s", e.msg);
    }
    m[i].size = size;
  }
  out->meshes._buffer = m;
  out->meshes._length = out->meshes._maximum = m ? (uint32_t)sc->norgans : 0;
  snprintf(out->version, sizeof out->version, "%s", cli_version());
  snprintf(out->compiler, sizeof out->compiler, "%s", build_compiler());
  snprintf(out->build_flags, sizeof out->build_flags, "%s", build_flags());
  snprintf(out->station, sizeof out->station, "%s", station ? station : "");
  return rc;
}

void scene_source_free(viscera_SceneSource *s) {
  free(s->text);
  free(s->meshes._buffer);
  memset(s, 0, sizeof *s);
}
