/* SPDX-License-Identifier: Apache-2.0 */
/* scene_source: the SceneSource sample (idl/viscera.idl, issue 16) of a
 * session: the scene file's text and digest, the digest and size of every
 * mesh it names (at its absolute path, so a re-simulation on this machine
 * finds it), and the build that runs it, so a recording needs nothing
 * beside it to be re-simulated. Published once at start (state QoS). */
#ifndef VISCERA_SCENE_SOURCE_H
#define VISCERA_SCENE_SOURCE_H

#include "scene.h"
#include "verr.h"
#include "viscera.h"

/* Fills *out (text heap-allocated: scene_source_free) from the scene as
 * loaded and its file (sc->path). A file or mesh that cannot be read is
 * named in err and the sample still filled (empty text or digest). */
int scene_source_fill(viscera_SceneSource *out, const scene_t *sc, const char *station, verr_t *err);
void scene_source_free(viscera_SceneSource *s);

#endif
