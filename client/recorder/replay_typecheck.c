/* SPDX-License-Identifier: Apache-2.0 */
#include "replay_typecheck.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <dds/ddsc/dds_opcodes.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsrt/heap.h>
#include <dds/ddsi/ddsi_typelib.h>
#include <dds/ddsi/ddsi_typewrap.h>
#include <dds/ddsi/ddsi_xt_impl.h>

#define OPS_MAX_DEPTH 16
#define OPS_MAX_STEPS (1u << 20)

typedef struct walk {
  const uint32_t *ops;
  uint32_t nops, size, steps;
  char *why;
  size_t n;
} walk_t;

static int bad(walk_t *w, uint32_t at, const char *what) {
  snprintf(w->why, w->n, "op %u (0x%08x): %s", at, at < w->nops ? w->ops[at] : 0u, what);
  return -1;
}

static int primitive(enum dds_stream_typecode t) {
  return t == DDS_OP_VAL_1BY || t == DDS_OP_VAL_2BY || t == DDS_OP_VAL_4BY || t == DDS_OP_VAL_8BY ||
         t == DDS_OP_VAL_BLN || t == DDS_OP_VAL_STR;
}

static int walk_from(walk_t *w, uint32_t p, unsigned depth, uint32_t elem_size);

/* The nested struct at p + jsr (elem_size bytes in memory). */
static int nested(walk_t *w, uint32_t p, uint32_t word, unsigned depth, uint32_t elem_size) {
  int32_t jsr = DDS_OP_ADR_JSR(word);
  int64_t target = (int64_t)p + jsr;
  if (jsr == 0 || target < 0 || target >= w->nops) return bad(w, p, "element program outside the stored program");
  if (elem_size == 0 || elem_size > (1u << 24)) return bad(w, p, "element size out of range");
  return walk_from(w, (uint32_t)target, depth + 1, elem_size);
}

/* One ADR at p; *len receives its length in words. */
static int adr(walk_t *w, uint32_t p, unsigned depth, uint32_t size, uint32_t *len) {
  uint32_t insn = w->ops[p];
  enum dds_stream_typecode type = DDS_OP_TYPE(insn), sub = DDS_OP_SUBTYPE(insn);
  if (p + 1 >= w->nops) return bad(w, p, "member runs past the end of the program");
  if (w->ops[p + 1] >= size) return bad(w, p, "member offset outside the sample");
  if (primitive(type)) {
    *len = 2;
    return 0;
  }
  if (type == DDS_OP_VAL_BST || type == DDS_OP_VAL_ENU) {
    *len = 3;
    return p + 2 < w->nops ? 0 : bad(w, p, "member runs past the end of the program");
  }
  if (type == DDS_OP_VAL_SEQ || type == DDS_OP_VAL_BSQ) {
    uint32_t b = type == DDS_OP_VAL_BSQ; /* the bound word */
    if (primitive(sub))
      *len = 2 + b;
    else if (sub == DDS_OP_VAL_BST || sub == DDS_OP_VAL_ENU)
      *len = 3 + b;
    else if (sub == DDS_OP_VAL_STU) {
      if (p + 3 + b >= w->nops) return bad(w, p, "member runs past the end of the program");
      uint32_t word = w->ops[p + 3 + b], jmp = DDS_OP_ADR_JMP(word);
      if (jmp != 0 && jmp < 4 + b) return bad(w, p, "jump into its own member");
      if (nested(w, p, word, depth, w->ops[p + 2 + b])) return -1;
      *len = jmp ? jmp : 4 + b;
    } else
      return bad(w, p, "sequence element kind replay does not verify");
    return p + *len <= w->nops ? 0 : bad(w, p, "member runs past the end of the program");
  }
  if (type == DDS_OP_VAL_ARR) {
    if (p + 2 >= w->nops || w->ops[p + 2] == 0) return bad(w, p, "array without a length");
    if (primitive(sub))
      *len = 3;
    else if (sub == DDS_OP_VAL_ENU)
      *len = 4;
    else if (sub == DDS_OP_VAL_BST)
      *len = 5;
    else if (sub == DDS_OP_VAL_STU) {
      if (p + 4 >= w->nops) return bad(w, p, "member runs past the end of the program");
      uint32_t word = w->ops[p + 3], jmp = DDS_OP_ADR_JMP(word);
      if (jmp != 0 && jmp < 5) return bad(w, p, "jump into its own member");
      if (nested(w, p, word, depth, w->ops[p + 4])) return -1;
      *len = jmp ? jmp : 5;
    } else
      return bad(w, p, "array element kind replay does not verify");
    return p + *len <= w->nops ? 0 : bad(w, p, "member runs past the end of the program");
  }
  return bad(w, p, "member kind replay does not verify");
}

/* A struct's program from p to its RTS; members lie inside `size` bytes.
 * An @appendable struct's program starts with DLC (its samples carry a
 * delimiter in XCDR2); DLC anywhere else, and PLC (mutable), are refused. */
static int walk_from(walk_t *w, uint32_t p, unsigned depth, uint32_t size) {
  if (depth > OPS_MAX_DEPTH) return bad(w, p, "nesting deeper than 16 levels");
  if (p < w->nops && w->ops[p] == DDS_OP_DLC) p++;
  while (p < w->nops) {
    if (++w->steps > OPS_MAX_STEPS) return bad(w, p, "program too long to verify");
    uint32_t insn = w->ops[p];
    if (insn == DDS_OP_RTS) return 0;
    if (DDS_OP(insn) != DDS_OP_ADR) return bad(w, p, "instruction replay does not verify");
    uint32_t len = 0;
    if (adr(w, p, depth, size, &len)) return -1;
    p += len;
  }
  return bad(w, p, "no end (RTS) before the end of the program");
}

int rp_ops_check(const uint32_t *ops, uint32_t nops, uint32_t size, uint32_t nkeys, const dds_key_descriptor_t *keys,
                 char *why, size_t n) {
  walk_t w = {ops, nops, size, 0, why, n};
  if (!ops || nops == 0) {
    snprintf(why, n, "no type program stored");
    return -1;
  }
  if (walk_from(&w, 0, 0, size)) return -1;
  /* Each key names a KOF whose offsets are ADR instructions of the program. */
  for (uint32_t k = 0; k < nkeys; k++) {
    uint32_t at = keys[k].m_offset;
    if (at >= nops || DDS_OP(ops[at]) != DDS_OP_KOF) return bad(&w, at, "key descriptor does not name a key op");
    uint32_t cnt = ops[at] & 0xffffu;
    if (cnt == 0 || cnt > 16 || at + cnt >= nops) return bad(&w, at, "key op out of range");
    for (uint32_t i = 1; i <= cnt; i++)
      if (ops[at + i] >= nops || DDS_OP(ops[ops[at + i]]) != DDS_OP_ADR)
        return bad(&w, at, "key op does not name a member");
  }
  return 0;
}

static int typeid_in(const dds_sequence_DDS_XTypes_TypeIdentifierTypeObjectPair *s, const ddsi_typeid_t *id) {
  for (uint32_t i = 0; i < s->_length; i++)
    if (!ddsi_typeid_compare((const ddsi_typeid_t *)&s->_buffer[i].type_identifier, id)) return 1;
  return 0;
}

/* Every pair's type object must hash to its identifier: NULL, or why not. */
static const char *pairs_ok(const dds_sequence_DDS_XTypes_TypeIdentifierTypeObjectPair *s) {
  for (uint32_t i = 0; i < s->_length; i++) {
    ddsi_typeid_t id;
    memset(&id, 0, sizeof id);
    if (ddsi_typeobj_get_hash_id(&s->_buffer[i].type_object, &id) != DDS_RETCODE_OK)
      return "a type object in the mapping cannot be hashed";
    int same = !ddsi_typeid_compare(&id, (const ddsi_typeid_t *)&s->_buffer[i].type_identifier);
    ddsi_typeid_fini(&id);
    if (!same) return "a type object in the mapping does not match its identifier";
  }
  return NULL;
}

/* The checks on the bytes, in this process. 0, or the index of the reason. */
enum { TC_OK, TC_INFO, TC_MAP, TC_INVALID, TC_HASH_MIN, TC_HASH_COMPLETE, TC_MIN_MISSING, TC_COMPLETE_MISSING };
static const char *const tc_reason[] = {"",
                                        "type information unreadable",
                                        "type mapping unreadable",
                                        "type information invalid",
                                        "a minimal type object in the mapping does not match its identifier",
                                        "a complete type object in the mapping does not match its identifier",
                                        "the minimal type is not in the type mapping",
                                        "the complete type is not in the type mapping"};

static int types_check_here(const unsigned char *typeinfo, uint32_t tilen, const unsigned char *typemap,
                            uint32_t tmlen) {
  struct ddsi_sertype_cdr_data ti = {tilen, (unsigned char *)typeinfo}, tm = {tmlen, (unsigned char *)typemap};
  ddsi_typeinfo_t *info = ddsi_typeinfo_deser(&ti);
  ddsi_typemap_t *map = info ? ddsi_typemap_deser(&tm) : NULL;
  int what = TC_OK;
  if (!info)
    what = TC_INFO;
  else if (!map)
    what = TC_MAP;
  else if (!ddsi_typeinfo_valid(info))
    what = TC_INVALID;
  else if (pairs_ok(&map->x.identifier_object_pair_minimal))
    what = TC_HASH_MIN;
  else if (pairs_ok(&map->x.identifier_object_pair_complete))
    what = TC_HASH_COMPLETE;
  else if (!typeid_in(&map->x.identifier_object_pair_minimal, ddsi_typeinfo_minimal_typeid(info)))
    what = TC_MIN_MISSING;
  else if (!typeid_in(&map->x.identifier_object_pair_complete, ddsi_typeinfo_complete_typeid(info)))
    what = TC_COMPLETE_MISSING;
  if (map) {
    ddsi_typemap_fini(map);
    ddsrt_free(map);
  }
  if (info) {
    ddsi_typeinfo_fini(info);
    ddsrt_free(info);
  }
  return what;
}

int rp_types_check(const unsigned char *typeinfo, uint32_t tilen, const unsigned char *typemap, uint32_t tmlen,
                   char *why, size_t n) {
  if (!typeinfo || tilen == 0 || !typemap || tmlen == 0) {
    snprintf(why, n, "type information or type mapping missing (%u and %u bytes)", tilen, tmlen);
    return -1;
  }
  /* Cyclone's own readers abort on some damaged mappings (fuzz: a changed
   * byte in a union discriminator), and dds_create_topic runs the same
   * readers: so they run first in a child process with a time limit, and
   * only bytes the child read to the end reach Cyclone in this one. */
  fflush(NULL);
  pid_t pid = fork();
  if (pid < 0) {
    snprintf(why, n, "cannot check the type information (fork failed)");
    return -1;
  }
  if (pid == 0) {
    /* A reader that loops spends CPU: 5 s of it end the child (SIGXCPU).
     * Wall time is only the backstop of a child that waits: on a loaded
     * machine a sound check can take seconds of it (seen under the
     * sanitizers with a CPU-bound process beside them). */
    struct rlimit cpu = {5, 6};
    setrlimit(RLIMIT_CPU, &cpu);
    alarm(60);
    _exit(types_check_here(typeinfo, tilen, typemap, tmlen));
  }
  int st = 0;
  while (waitpid(pid, &st, 0) < 0)
    if (errno != EINTR) {
      snprintf(why, n, "cannot check the type information (wait failed)");
      return -1;
    }
  if (WIFSIGNALED(st)) {
    snprintf(why, n, "type information or mapping makes Cyclone's reader fail (signal %d)", WTERMSIG(st));
    return -1;
  }
  int code = WIFEXITED(st) ? WEXITSTATUS(st) : TC_MAP;
  if (code == TC_OK) return 0;
  snprintf(why, n, "%s", code < (int)(sizeof tc_reason / sizeof *tc_reason) ? tc_reason[code] : "type check failed");
  return -1;
}
