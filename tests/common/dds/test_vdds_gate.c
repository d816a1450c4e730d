/* SPDX-License-Identifier: Apache-2.0 */
/* vdds_gate (issue 15.1): the verdict for each sample (key bound, content
 * check, blocked writers per key and for every key, unblocking, the
 * bounded table), then the gate in front of a real reader in one process
 * (domain 188): 200 ToolCommands for new tool ids make no instance beyond
 * the bound, and a blocked writer's flood on tool 0 takes no place in the
 * history, so another writer's sample is still there to take. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "dds/vdds_gate.h"
#include "viscera.h"

static int finite_x(const void *sample, void *arg) {
  (void)arg;
  return isfinite(((const viscera_ToolCommand *)sample)->position[0]) ? 0 : 3;
}

static viscera_ToolCommand cmd(uint32_t tool, float x) {
  viscera_ToolCommand c;
  memset(&c, 0, sizeof c);
  c.tool_id = tool;
  c.position[0] = x;
  c.orientation[0] = 1;
  c.max_force = 4;
  return c;
}

static void test_verdicts(void) {
  vdds_gate_t g;
  vdds_gate_init(&g, 2, finite_x, NULL);
  viscera_ToolCommand ok0 = cmd(0, 0), ok1 = cmd(1, 0), far = cmd(2, 0), nan = cmd(0, NAN);
  CHECK(vdds_gate_accepts(&g, &ok0, 11) == 1);
  CHECK(vdds_gate_accepts(&g, &far, 11) == 0 && g.out_of_range == 1 && g.last_refused_key == 2);
  CHECK(vdds_gate_accepts(&g, &nan, 11) == 0 && g.refused == 1 && g.reason[3] == 1);
  /* Writer 11 blocked for tool 0 only; writer 12 untouched. */
  vdds_gate_block(&g, 11, 0);
  vdds_gate_block(&g, 11, 0); /* idempotent */
  CHECK(g.nblocked == 1);
  CHECK(vdds_gate_accepts(&g, &ok0, 11) == 0 && g.from_blocked == 1);
  CHECK(vdds_gate_accepts(&g, &ok1, 11) == 1);
  CHECK(vdds_gate_accepts(&g, &ok0, 12) == 1);
  /* Every key. */
  vdds_gate_block(&g, 12, VDDS_GATE_ANY_KEY);
  CHECK(vdds_gate_accepts(&g, &ok1, 12) == 0);
  /* The tool's role changed: its blocks go, the others stay. */
  vdds_gate_unblock_key(&g, 0);
  CHECK(vdds_gate_accepts(&g, &ok0, 11) == 1);
  CHECK(vdds_gate_accepts(&g, &ok1, 12) == 0);
  vdds_gate_unblock_key(&g, VDDS_GATE_ANY_KEY);
  CHECK(g.nblocked == 0 && vdds_gate_accepts(&g, &ok1, 12) == 1);
  /* Bounded: the oldest entry is recycled. */
  for (dds_instance_handle_t w = 100; w < 100 + VDDS_GATE_BLOCK_CAP + 5; w++) vdds_gate_block(&g, w, 0);
  CHECK(g.nblocked == VDDS_GATE_BLOCK_CAP);
  CHECK(vdds_gate_accepts(&g, &ok0, 100) == 1);                           /* recycled */
  CHECK(vdds_gate_accepts(&g, &ok0, 100 + VDDS_GATE_BLOCK_CAP + 4) == 0); /* newest kept */
  CHECK(vdds_gate_dropped(&g) == g.out_of_range + g.refused + g.from_blocked);
  vdds_gate_destroy(&g);
}

static int count_instances(dds_entity_t r, int *tool0) {
  void *s[64] = {0};
  dds_sample_info_t si[64];
  int n = dds_take(r, s, si, 64, 64), distinct = 0;
  dds_instance_handle_t seen[64];
  *tool0 = 0;
  for (int i = 0; i < n; i++) {
    int dup = 0;
    for (int j = 0; j < distinct; j++) dup |= seen[j] == si[i].instance_handle;
    if (!dup) seen[distinct++] = si[i].instance_handle;
    if (si[i].valid_data && ((const viscera_ToolCommand *)s[i])->tool_id == 0) (*tool0)++;
  }
  if (n > 0) dds_return_loan(r, s, n);
  return distinct;
}

static void test_reader(void) {
  vdds_t v;
  verr_t err;
  if (vdds_open(&v, 188, "hardnet/gate", &err)) {
    fprintf(stderr, "%s\n", err.msg);
    CHECK(0);
    return;
  }
  vdds_gate_t g;
  vdds_gate_init(&g, 4, finite_x, NULL);
  dds_entity_t r = vdds_reader_gated(&v, VT_TOOL_COMMAND, &g, 4, 4, NULL, &err);
  dds_entity_t w = vdds_writer(&v, VT_TOOL_COMMAND, &err), w2 = vdds_writer(&v, VT_TOOL_COMMAND, &err);
  CHECK(r > 0 && w > 0 && w2 > 0);
  /* The participant's own writers are not filtered: a plain reader sees all. */
  for (uint32_t t = 0; t < 200; t++) {
    viscera_ToolCommand c = cmd(t, 0);
    dds_write(w, &c);
  }
  int tool0 = 0;
  CHECK(count_instances(r, &tool0) == 4);
  CHECK(g.out_of_range == 196);
  /* w blocked on tool 0; w2's one sample stays in the depth-4 history. */
  dds_instance_handle_t hw = 0;
  CHECK(dds_get_instance_handle(w, &hw) == 0);
  vdds_gate_block(&g, hw, 0);
  viscera_ToolCommand good = cmd(0, 0.01f), bad = cmd(0, NAN);
  dds_write(w2, &good);
  for (int i = 0; i < 100; i++) {
    dds_write(w, &good);
    dds_write(w2, &bad);
  }
  count_instances(r, &tool0);
  CHECK(tool0 == 1);
  CHECK(g.from_blocked == 100 && g.refused == 100);
  vdds_close(&v);
  vdds_gate_destroy(&g);
}

int main(void) {
  test_verdicts();
  test_reader();
  return check_report("test_vdds_gate");
}
