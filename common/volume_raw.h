/* SPDX-License-Identifier: Apache-2.0 */
/* volume_raw: what the format readers of volume_mesh.c hand over before
 * validation: node tags as the file wrote them and tetrahedra naming nodes
 * by those tags, each with its line for messages. Internal to volume_*.c. */
#ifndef VISCERA_VOLUME_RAW_H
#define VISCERA_VOLUME_RAW_H

#include <stddef.h>
#include <stdint.h>

#include "text_scan.h"
#include "verr.h"

typedef struct volume_raw {
  size_t nnodes, node_cap;
  long long *tag; /* nnodes */
  double *x;      /* 3 nnodes */
  size_t ntets, tet_cap;
  long long *corner; /* 4 ntets, node tags */
  int *line;         /* ntets */
  size_t skipped;
} volume_raw_t;

int volume_raw_add_node(volume_raw_t *r, long long tag, const double p[3], verr_t *err);
int volume_raw_add_tet(volume_raw_t *r, const long long c[4], int line, verr_t *err);
void volume_raw_free(volume_raw_t *r);

/* Readers: fill r from an open scanner; messages name s->path and lines. */
int volume_read_msh(text_scan_t *s, volume_raw_t *r, verr_t *err);
int volume_read_vtk(text_scan_t *s, volume_raw_t *r, verr_t *err);
/* node and ele are two scanners over the .node and .ele files. */
int volume_read_tetgen(text_scan_t *node, text_scan_t *ele, volume_raw_t *r, verr_t *err);

#endif
