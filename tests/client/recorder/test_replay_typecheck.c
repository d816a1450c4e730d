/* SPDX-License-Identifier: Apache-2.0 */
/* test_replay_typecheck: the checks replay runs on a stored descriptor
 * before Cyclone sees it (replay_typecheck.c, issue 15 item 4). Every
 * product type's own descriptor passes them (the verifier is strict: a new
 * IDL construct it does not know must show up here, not as a replay that
 * drops a topic); the damage the issue found is refused with a reason:
 * missing, cut or foreign type mapping, a program whose nested element is
 * the member itself, jumps out of the program, a member outside the
 * sample, a key op that names nothing. */
#include <stdlib.h>
#include <string.h>

#include <dds/ddsi/ddsi_cdrstream.h>

#include "check.h"
#include "replay_typecheck.h"
#include "viscera.h"

/* Which bytes of each mapping the sweep changes (CMakeLists.txt). */
#ifndef TYPECHECK_STRIDE
#define TYPECHECK_STRIDE 3
#endif

static const dds_topic_descriptor_t *const descs[] = {
    &viscera_SceneInfo_desc,       &viscera_MeshState_desc,    &viscera_MeshDelta_desc,  &viscera_ToolCommand_desc,
    &viscera_ContactFeedback_desc, &viscera_SessionEvent_desc, &viscera_Metrics_desc,    &viscera_SessionControl_desc,
    &viscera_ToolRole_desc,        &viscera_ObjectState_desc,  &viscera_ToolMetrics_desc};

static uint32_t nops_of(const dds_topic_descriptor_t *d) {
  return dds_stream_countops(d->m_ops, d->m_nkeys, d->m_keys);
}

static int ops_ok(const dds_topic_descriptor_t *d, const uint32_t *ops, uint32_t n, char *why) {
  return rp_ops_check(ops, n, d->m_size, d->m_nkeys, d->m_keys, why, 200) == 0;
}

int main(void) {
  char why[200];
  const char *dom = getenv("VISCERA_DOMAIN");
  dds_entity_t pp = dds_create_participant(dom ? (dds_domainid_t)atoi(dom) : 195, NULL, NULL);
  CHECK(pp > 0);
  for (size_t i = 0; i < sizeof descs / sizeof *descs; i++) {
    const dds_topic_descriptor_t *d = descs[i];
    uint32_t n = nops_of(d);
    if (!ops_ok(d, d->m_ops, n, why)) {
      fprintf(stderr, "  %s: %s\n", d->m_typename, why);
      CHECK(!"every product type passes rp_ops_check");
    }
    const unsigned char *ti = d->type_information.data, *tm = d->type_mapping.data;
    uint32_t til = d->type_information.sz, tml = d->type_mapping.sz;
    if (rp_types_check(ti, til, tm, tml, why, sizeof why)) {
      fprintf(stderr, "  %s: %s\n", d->m_typename, why);
      CHECK(!"every product type passes rp_types_check");
    }
    /* Damaged type information. */
    CHECK(rp_types_check(NULL, 0, tm, tml, why, sizeof why) == -1 && strstr(why, "missing"));
    CHECK(rp_types_check(ti, til, NULL, 0, why, sizeof why) == -1 && strstr(why, "missing"));
    CHECK(rp_types_check(ti, til, tm, tml / 2, why, sizeof why) == -1);
    CHECK(rp_types_check(ti, til / 2, tm, tml, why, sizeof why) == -1);
    const dds_topic_descriptor_t *other = descs[(i + 1) % (sizeof descs / sizeof *descs)];
    CHECK(rp_types_check(ti, til, other->type_mapping.data, other->type_mapping.sz, why, sizeof why) == -1 &&
          strstr(why, "not in the type mapping"));
    /* A single-byte change at every TYPECHECK_STRIDE-th byte of the mapping: never a crash (this test runs
     * under the sanitizers too); most are refused (unreadable, or a type
     * object no longer hashing to its identifier); the rest are bytes the
     * readers do not depend on. */
    unsigned char *tm2 = malloc(tml);
    size_t refused = 0;
    uint32_t tried = 0;
    for (uint32_t k = 0; k < tml; k += TYPECHECK_STRIDE, tried++) {
      memcpy(tm2, tm, tml);
      tm2[k] ^= 0x5a;
      if (rp_types_check(ti, til, tm2, tml, why, sizeof why)) {
        refused++;
        continue;
      }
      /* Accepted: Cyclone takes it (what replay does next). */
      dds_topic_descriptor_t copy = *d;
      copy.type_mapping.data = tm2;
      char name[64];
      snprintf(name, sizeof name, "typecheck_%zu_%u", i, k);
      dds_entity_t tp = dds_create_topic(pp, &copy, name, NULL, NULL);
      if (tp > 0) dds_delete(tp);
    }
    free(tm2);
    printf("%s: %zu of %u one-byte changes of the type mapping refused, Cyclone took the rest\n", d->m_typename,
           refused, tried);
    CHECK(refused * 2 > tried);
    /* Damaged programs. */
    uint32_t *ops = malloc((n + 8) * sizeof *ops);
    memcpy(ops, d->m_ops, n * sizeof *ops);
    ops[0] = DDS_OP_ADR | DDS_OP_TYPE_SEQ | DDS_OP_SUBTYPE_STU; /* element program: itself */
    ops[1] = 0;
    ops[2] = 16;
    ops[3] = 4u << 16;
    CHECK(!ops_ok(d, ops, n, why) && strstr(why, "op 0"));
    ops[3] = (4u << 16) | 0xfff0u; /* 16 ops before the start */
    CHECK(!ops_ok(d, ops, n, why) && strstr(why, "outside the stored program"));
    memcpy(ops, d->m_ops, n * sizeof *ops);
    uint32_t first = ops[0] == DDS_OP_DLC; /* @appendable: the program starts with DLC */
    CHECK(first == 1);                     /* every product type is @appendable (idl/viscera.idl) */
    ops[first + 1] = d->m_size;            /* the first member just outside the sample */
    CHECK(!ops_ok(d, ops, n, why) && strstr(why, "offset outside the sample"));
    memcpy(ops, d->m_ops, n * sizeof *ops);
    ops[first] = DDS_OP_DLC; /* a DLC where the first member was: refused */
    CHECK(!ops_ok(d, ops, n, why) && strstr(why, "op 1"));
    memcpy(ops, d->m_ops, n * sizeof *ops);
    for (uint32_t k = 0; k < n; k++) ops[k] = ops[k] == DDS_OP_RTS ? 0xffffffffu : ops[k]; /* no end */
    CHECK(!ops_ok(d, ops, n, why));
    memset(ops, 0, n * sizeof *ops);
    CHECK(d->m_nkeys == 0 || (!ops_ok(d, ops, n, why) && strstr(why, "key")));
    CHECK(!ops_ok(d, NULL, 0, why));
    free(ops);
  }
  dds_delete(pp);
  return check_report("test_replay_typecheck");
}
