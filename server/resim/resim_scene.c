/* SPDX-License-Identifier: Apache-2.0 */
#include "resim/resim_scene.h"

#include <stdlib.h>
#include <string.h>

#include "sha256.h"

/* Line `*p` of a text up to its newline: its length; *p moves past it. */
static size_t next_line(const char **p, const char **line) {
  *line = *p;
  const char *nl = strchr(*p, '\n');
  size_t n = nl ? (size_t)(nl - *p) : strlen(*p);
  *p += nl ? n + 1 : n;
  return n;
}

/* Names the lines where `file` differs from the recorded text (by
 * position: the first 5, then a count). Returns the number of them. */
static int diff_text(const char *recorded, const char *file, FILE *out) {
  const char *a = recorded, *b = file;
  int line = 0, ndiff = 0;
  while (*a || *b) {
    const char *la, *lb;
    size_t na = next_line(&a, &la), nb = next_line(&b, &lb);
    line++;
    if (na == nb && !memcmp(la, lb, na)) continue;
    if (++ndiff <= 5)
      fprintf(out, "SCENE differs line=%d recording=\"%.*s\" file=\"%.*s\"\n", line, (int)(na > 120 ? 120 : na), la,
              (int)(nb > 120 ? 120 : nb), lb);
  }
  if (ndiff > 5) fprintf(out, "SCENE differs lines=%d (first 5 above)\n", ndiff);
  return ndiff;
}

/* Every organ's mesh against the recorded digest; the number that differ
 * (missing, other bytes), each named. */
static int check_meshes(const scene_t *sc, const resim_source_t *src, FILE *out, char *first, size_t n) {
  int bad = 0;
  for (size_t i = 0; i < sc->norgans; i++) {
    char hex[SHA256_HEX_LEN] = "";
    uint64_t size = 0;
    verr_t e;
    int unreadable = sha256_file(sc->organs[i].mesh, hex, &size, &e) != 0;
    const char *want = i < src->nmeshes ? src->meshes[i].sha256 : "";
    if (!unreadable && !strcmp(hex, want)) continue;
    bad++;
    char what[600];
    if (unreadable)
      snprintf(what, sizeof what, "organ '%s': mesh %s: %s", sc->organs[i].name, sc->organs[i].mesh, e.msg);
    else
      snprintf(what, sizeof what,
               "organ '%s': mesh %s has sha256 %.16s... (%llu bytes), the recording %.16s... (%llu bytes)",
               sc->organs[i].name, sc->organs[i].mesh, hex, (unsigned long long)size, want[0] ? want : "none",
               (unsigned long long)(i < src->nmeshes ? src->meshes[i].size : 0));
    fprintf(out, "SCENE differs %s\n", what);
    if (bad == 1) snprintf(first, n, "%s", what);
  }
  return bad;
}

/* A mesh not at the path the server read it from, looked for by its file
 * name in mesh_dir and taken only when its digest is the recorded one. */
static void relocate_meshes(scene_t *sc, const resim_source_t *src, const char *mesh_dir, FILE *out) {
  for (size_t i = 0; mesh_dir && i < sc->norgans && i < src->nmeshes; i++) {
    char hex[SHA256_HEX_LEN];
    uint64_t size;
    verr_t e;
    if (!sha256_file(sc->organs[i].mesh, hex, &size, &e) && !strcmp(hex, src->meshes[i].sha256)) continue;
    const char *base = strrchr(sc->organs[i].mesh, '/');
    base = base ? base + 1 : sc->organs[i].mesh;
    char cand[sizeof sc->organs[i].mesh];
    int n = snprintf(cand, sizeof cand, "%s/%s", mesh_dir, base);
    if (n <= 0 || (size_t)n >= sizeof cand) continue;
    if (sha256_file(cand, hex, &size, &e) || strcmp(hex, src->meshes[i].sha256)) continue;
    fprintf(out, "SCENE mesh organ=%s found=%s (not at %s)\n", sc->organs[i].name, cand, sc->organs[i].mesh);
    memcpy(sc->organs[i].mesh, cand, sizeof cand);
  }
}

int resim_scene_load(scene_t *sc, const char *path, const char *mesh_dir, const resim_recording_t *rec, FILE *report,
                     verr_t *err) {
  const resim_source_t *src = &rec->source;
  char first[600] = "";
  if (path) {
    if (scene_load(path, sc, err)) return -1;
    if (!src->have) {
      fprintf(report, "SCENE source=file %s (the recording holds no scene text to compare with)\n", path);
      return 0;
    }
    FILE *f = fopen(path, "rb");
    char *text = NULL;
    size_t cap = 0, len = 0;
    if (f) {
      char buf[4096];
      size_t n;
      while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
        if (len + n + 1 > cap) {
          cap = 2 * (len + n + 1);
          char *p = realloc(text, cap);
          if (!p) break;
          text = p;
        }
        memcpy(text + len, buf, n);
        len += n;
      }
      fclose(f);
      if (text) text[len] = 0;
    }
    int lines = text ? diff_text(src->text, text, report) : -1;
    free(text);
    int meshes = check_meshes(sc, src, report, first, sizeof first);
    fprintf(report, "SCENE source=file %s text=%s meshes=%s\n", path, lines == 0 ? "same" : "differs",
            meshes ? "differ" : "same");
    return 0;
  }
  if (!src->have)
    return verr_set(err, "the recording holds no SceneSource (recorded before issue 16, or the server's sample was "
                         "lost): give the scene with --scene FILE");
  /* Relative mesh paths as the server resolved them: against its scene file's directory. */
  char dir[sizeof src->path];
  snprintf(dir, sizeof dir, "%s", src->path);
  char *slash = strrchr(dir, '/');
  if (slash)
    slash == dir ? (void)(dir[1] = 0) : (void)(*slash = 0);
  else
    dir[0] = 0;
  if (scene_load_string(src->text, src->path, dir, sc, err)) return -1;
  snprintf(sc->path, sizeof sc->path, "%.1000s", src->path);
  relocate_meshes(sc, src, mesh_dir, report);
  if (check_meshes(sc, src, report, first, sizeof first))
    return verr_set(
        err, "the recorded scene's meshes are not the ones the session ran: %s (--mesh-dir DIR names where copies are)",
        first);
  fprintf(report, "SCENE source=recording %s sha256=%.16s meshes=%zu verified\n", src->path, src->text_sha256,
          sc->norgans);
  return 0;
}
