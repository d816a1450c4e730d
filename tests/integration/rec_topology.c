/* SPDX-License-Identifier: Apache-2.0 */
/* rec_topology: reads a session recording (rec_read.h) and prints every
 * recorded MeshState keyframe and EVENT_TOPOLOGY_CHANGED SessionEvent,
 * decoded with the compiled-in descriptors:
 *   MESHSTATE organ=N topology=V keyframe=K vertices=NV triangles=NT
 *   TOPOLOGY_EVENT organ=N value=X text
 * Exit 1 when the file cannot be read, is damaged or a sample does not
 * decode.
 * usage: rec_topology FILE.db */
#include <stdio.h>

#include "rec_read.h"
#include "viscera.h"

static int on_state(void *arg, const void *sample, const recfile_row_t *row) {
  (void)arg, (void)row;
  const viscera_MeshState *m = sample;
  printf("MESHSTATE organ=%u topology=%u keyframe=%u vertices=%u triangles=%u\n", m->organ_id, m->topology_version,
         m->keyframe_seq, m->positions._length / 3, m->triangles._length / 3);
  return 0;
}

static int on_event(void *arg, const void *sample, const recfile_row_t *row) {
  (void)arg, (void)row;
  const viscera_SessionEvent *e = sample;
  if (e->kind == viscera_EVENT_TOPOLOGY_CHANGED)
    printf("TOPOLOGY_EVENT organ=%d value=%.0f %s\n", (int)e->organ_id, e->value, e->text);
  return 0;
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: rec_topology FILE.db\n");
    return 2;
  }
  recfile_t *rf = NULL;
  verr_t err;
  if (recfile_open(&rf, argv[1], &err) < 0) {
    fprintf(stderr, "rec_topology: %s\n", err.msg);
    return 1;
  }
  int bad = rec_read_topic("rec_topology", rf, "viscera_MeshState", &viscera_MeshState_desc, on_state, NULL);
  bad += rec_read_topic("rec_topology", rf, "viscera_SessionEvent", &viscera_SessionEvent_desc, on_event, NULL);
  recfile_close(rf);
  return bad ? 1 : 0;
}
