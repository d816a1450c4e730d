/* SPDX-License-Identifier: Apache-2.0 */
/* replay_typecheck: a stored type descriptor checked before Cyclone DDS
 * sees it (issue 15: a NULL or damaged type mapping crashed
 * dds_create_topic, damaged ops made dds_stream_countops loop for ever).
 *
 * rp_ops_check walks the stored op program the way Cyclone's cdrstream
 * does, with every offset, jump and nesting bounded: only the instructions
 * the IDL compiler emits for structs of primitives, strings, enums, arrays,
 * sequences and nested structs (ADR, RTS, KOF) are accepted; a member
 * offset must lie inside the sample size; every walk ends at an RTS inside
 * the program. rp_types_check deserializes the stored XTypes type
 * information and type mapping with Cyclone's own readers and checks that
 * every type object hashes to the identifier stored with it and that the
 * topic's minimal and complete identifiers are in the mapping (the
 * descriptor is rebuilt from what is stored, a mismatch refused). Cyclone's
 * readers abort on some damaged mappings, so rp_types_check runs them in a
 * child process (fork, 5 s limit): a reader that dies or hangs there means
 * refused. Both return 0, or -1 with the reason in `why`. rp_ops_check is a
 * pure function; rp_types_check forks (call it from one thread at a time
 * with no lock held that the child would need). */
#ifndef VISCERA_REPLAY_TYPECHECK_H
#define VISCERA_REPLAY_TYPECHECK_H

#include <stddef.h>
#include <stdint.h>

#include <dds/dds.h>

int rp_ops_check(const uint32_t *ops, uint32_t nops, uint32_t size, uint32_t nkeys, const dds_key_descriptor_t *keys,
                 char *why, size_t n);
int rp_types_check(const unsigned char *typeinfo, uint32_t tilen, const unsigned char *typemap, uint32_t tmlen,
                   char *why, size_t n);

#endif
