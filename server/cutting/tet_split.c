/* SPDX-License-Identifier: Apache-2.0 */
#include "cutting/tet_split.h"

#include <math.h>

#include "cutting/tet_cut.h"

const int TET_SPLIT_EDGE[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

/* A mask separates the nodes iff it is exactly the set of edges between two
 * non-empty groups: put node 0 in group 0, every other node k in the group
 * that edge (0, k) says, then every edge must agree. */
tet_split_case_t tet_split_classify(unsigned mask, int side[4]) {
  mask &= 63u;
  if (!mask) return TET_SPLIT_NONE;
  int s[4] = {0, (mask >> 0) & 1, (mask >> 1) & 1, (mask >> 2) & 1};
  int consistent = 1, count = 0;
  for (int e = 0; e < 6; e++) {
    int cut = (mask >> e) & 1;
    count += cut;
    if (cut != (s[TET_SPLIT_EDGE[e][0]] != s[TET_SPLIT_EDGE[e][1]])) consistent = 0;
  }
  if (consistent && (count == 3 || count == 4)) {
    if (side)
      for (int k = 0; k < 4; k++) side[k] = s[k];
    return count == 3 ? TET_SPLIT_G1 : TET_SPLIT_G2;
  }
  return count == 1 ? TET_SPLIT_P1 : count == 2 ? TET_SPLIT_P2 : TET_SPLIT_P3;
}

double tet_cut_rest_edge(double d, double l_ap, double l_pb) {
  double l = l_ap + l_pb;
  return l > 0 ? d * l_ap / l : 0;
}

/* D is where the ray A->P meets BC: D = (l2 B + l3 C) / (l2 + l3), so
 * |DC| = d2 l2 / (l2 + l3); the law of cosines at C (angle gamma between CB
 * and CA) gives |AD|, and P = l1 A + (l2 + l3) D gives |AP| = (l2 + l3) |AD|. */
double tet_cut_rest_face(double d1, double d2, double d3, double l1, double l2, double l3) {
  (void)l1;
  double s = l2 + l3;
  if (!(s > 0) || !(d2 > 0) || !(d3 > 0)) return 0;
  double cg = (d2 * d2 + d3 * d3 - d1 * d1) / (2 * d2 * d3);
  double dc = d2 * l2 / s;
  double ad2 = d3 * d3 + dc * dc - 2 * d3 * dc * cg;
  return s * sqrt(ad2 > 0 ? ad2 : 0);
}
