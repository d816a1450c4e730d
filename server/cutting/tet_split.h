/* SPDX-License-Identifier: Apache-2.0 */
/* tet_split: the case table of a tetrahedron's cut state (docs/methods.md C §5.2,
 * figs. 8-9) and the seed's rest-length rules. Internal to tet_cut.c and its
 * tests; the splitting itself (recursive bisection, see tet_cut.h) is in
 * tet_cut.c because it needs the edge table.
 *
 * Edges of a tetrahedron (a0, a1, a2, a3) are numbered
 * 0:(0,1) 1:(0,2) 2:(0,3) 3:(1,2) 4:(1,3) 5:(2,3); a cut state is a 6-bit
 * mask of the cut ones. */
#ifndef VISCERA_TET_SPLIT_H
#define VISCERA_TET_SPLIT_H

typedef enum tet_split_case {
  TET_SPLIT_NONE = 0, /* no edge cut */
  TET_SPLIT_G1,       /* general: 3 edges around one node cut, 1 | 3 */
  TET_SPLIT_G2,       /* general: 4 edges cut, 2 | 2 */
  TET_SPLIT_P1,       /* partial: one edge */
  TET_SPLIT_P2,       /* partial: two edges */
  TET_SPLIT_P3        /* partial: three or more edges that separate nothing */
} tet_split_case_t;

extern const int TET_SPLIT_EDGE[6][2];

/* Classifies a cut mask; for G1 and G2 writes the side (0 or 1) of each of
 * the four nodes into side (may be NULL). */
tet_split_case_t tet_split_classify(unsigned mask, int side[4]);

#endif
