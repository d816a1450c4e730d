/* SPDX-License-Identifier: Apache-2.0 */
/* rec_mesh: the mesh a recording ends on. Reads a session recording
 * (rec_read.h), feeds organ ORGAN's MeshState keyframes and MeshDelta samples
 * in recording order into an organ_state (as a viewer rebuilds the mesh from
 * the wire) and writes the result as OBJ with the viewer's first line
 * ("# organ <id> topology <v> keyframe <k> frame <f>"), so obj_compare can
 * hold it against the server's --final-mesh. Exit 0 written, 1 on a bad
 * recording or no keyframe. usage: rec_mesh FILE.db ORGAN OUT.obj */
#include <stdio.h>
#include <stdlib.h>

#include "mesh.h"
#include "rec_read.h"
#include "view/organ_state.h"
#include "viscera.h"

typedef struct ctx {
  organ_state_t st;
  uint32_t organ;
  int bad;
} ctx_t;

/* Keyframes first (the last one per organ wins), then every delta in order:
 * deltas of older keyframes are stale and ignored, the newest of the last
 * keyframe is what the mesh ends on (deltas are cumulative). */
static int on_key(void *arg, const void *sample, const recfile_row_t *row) {
  ctx_t *c = arg;
  const viscera_MeshState *s = sample;
  verr_t err;
  (void)row;
  if (s->organ_id != c->organ) return 0;
  if (organ_state_set_keyframe(&c->st, s->topology_version, s->keyframe_seq, s->sim_time_ns, s->positions._buffer,
                               s->positions._length, s->triangles._buffer, s->triangles._length, &err) < 0) {
    fprintf(stderr, "rec_mesh: keyframe refused: %s\n", err.msg);
    c->bad++;
  }
  return 0;
}

static int on_delta(void *arg, const void *sample, const recfile_row_t *row) {
  ctx_t *c = arg;
  const viscera_MeshDelta *d = sample;
  verr_t err;
  (void)row;
  if (d->organ_id != c->organ) return 0;
  organ_delta_t od = {.topology_version = d->topology_version,
                      .keyframe_seq = d->keyframe_seq,
                      .frame_seq = d->frame_seq,
                      .sim_time_ns = d->sim_time_ns,
                      .quant_step = d->quant_step,
                      .indices = d->indices._buffer,
                      .count = d->indices._length,
                      .dq = d->dq._buffer,
                      .dq_len = d->dq._length};
  if (organ_state_delta(&c->st, &od, &err) < 0) {
    fprintf(stderr, "rec_mesh: delta refused: %s\n", err.msg);
    c->bad++;
  }
  return 0;
}

int main(int argc, char **argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: rec_mesh FILE.db ORGAN OUT.obj\n");
    return 2;
  }
  ctx_t c = {.organ = (uint32_t)atoi(argv[2])};
  verr_t err;
  recfile_t *rf = NULL;
  if (recfile_open(&rf, argv[1], &err) < 0) {
    fprintf(stderr, "rec_mesh: %s\n", err.msg);
    return 1;
  }
  c.bad += rec_read_topic("rec_mesh", rf, "viscera_MeshState", &viscera_MeshState_desc, on_key, &c);
  c.bad += rec_read_topic("rec_mesh", rf, "viscera_MeshDelta", &viscera_MeshDelta_desc, on_delta, &c);
  recfile_close(rf);
  int rc = 1;
  mesh_t m;
  if (!c.st.have_key)
    fprintf(stderr, "rec_mesh: %s: no keyframe of organ %u\n", argv[1], c.organ);
  else if (mesh_alloc(&m, c.st.nverts, c.st.ntris, &err) == 0) {
    for (size_t i = 0; i < 3 * c.st.nverts; i++) m.pos[i] = c.st.cur[i];
    for (size_t i = 0; i < 3 * c.st.ntris; i++) m.tris[i] = c.st.tris[i];
    char comment[128];
    snprintf(comment, sizeof comment, "organ %u topology %u keyframe %u frame %lld", c.organ, c.st.topology_version,
             c.st.keyframe_seq, organ_state_frame_seq(&c.st));
    rc = mesh_write_obj(&m, argv[3], comment, &err) < 0 || c.bad ? 1 : 0;
    mesh_free(&m);
  }
  organ_state_free(&c.st);
  return rc;
}
