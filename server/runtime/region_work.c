/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/region_work.h"

#include "physics/model_mass_spring.h"

region_work_t runtime_region_work(const runtime_t *rt) {
  region_work_t w = {0};
  for (size_t i = 0; i < rt->norgans; i++) {
    ms_region_counts_t c;
    if (!rt->organs[i].model || model_mass_spring_region_counts(rt->organs[i].model, &c) != 0) continue;
    w.organs++;
    w.node_updates += c.node_updates;
    w.block_evals += c.block_evals;
  }
  return w;
}
