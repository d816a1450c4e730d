/* SPDX-License-Identifier: Apache-2.0 */
/* export_scene: the recorded organ meshes as Foxglove scene primitives,
 * for recinfo --export mcap --foxglove-scene: one extra MCAP channel
 * "/viscera/scene" (message encoding json, schema foxglove.SceneUpdate,
 * schema encoding jsonschema) whose messages carry one entity per organ, a
 * TriangleListPrimitive of its current surface (frame "world", metres, the
 * organ's colour from SceneInfo), so Foxglove's 3D panel shows the tissue
 * deform and the cuts. Built from MeshState keyframes plus MeshDelta
 * displacements (within quant_step / 2, idl/viscera.idl), at most one
 * update per organ every EXPORT_SCENE_PERIOD_NS of source time. Uses the
 * compiled types: a sample that does not decode is skipped and counted. */
#ifndef VISCERA_EXPORT_SCENE_H
#define VISCERA_EXPORT_SCENE_H

#include <stdint.h>

#include "mcap_writer.h"
#include "recording/recfile.h"

#define EXPORT_SCENE_PERIOD_NS 100000000ull /* 10 Hz */

typedef struct export_scene export_scene_t;

/* Adds the schema and channel (ids given) to w; NULL when out of memory. */
export_scene_t *export_scene_open(mcap_writer_t *w, uint16_t schema_id, uint16_t channel_id, verr_t *err);
/* Feeds one recorded row (any topic; only SceneInfo, MeshState and
 * MeshDelta data rows matter); may write a message. */
int export_scene_row(export_scene_t *s, const char *topic, const recfile_row_t *row, verr_t *err);
/* Messages written and samples skipped; frees s. */
void export_scene_close(export_scene_t *s, uint64_t *messages, uint64_t *skipped);

#endif
