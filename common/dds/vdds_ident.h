/* SPDX-License-Identifier: Apache-2.0 */
/* vdds_ident: who a viscera process says it is, in its DDS participant's
 * USER_DATA QoS, and how a reader turns received USER_DATA back into safe
 * text.
 *
 * Format (one line, at most VDDS_IDENT_MAX-1 bytes, printable ASCII):
 *   "viscera role=<role> [tool=<n> ]host=<hostname> pid=<pid>[ station=<name>][ cert=<hex>]"
 * cert= is present only under DDS Security: the DER subject of the
 * process's certificate, which secure readers verify (vdds_subject.h).
 * Every main calls vdds_set_role() (and the haptic client vdds_set_tool())
 * before creating its participant; vdds_open() and the recorder/replay,
 * which create participants themselves, use vdds_participant_qos().
 *
 * The role is the process's CLAIM: anyone can put any USER_DATA in a
 * participant. With DDS Security it is the access-control permissions
 * (deploy/pki.sh) that decide what a participant may publish, never this
 * string; readers use it for labelling (recordings, dashboards) only.
 *
 * USER_DATA received from the network is untrusted: vdds_ident_sanitize()
 * bounds it and replaces every byte that is not printable ASCII.
 * Not thread-safe while setting the role (done once in main). */
#ifndef VISCERA_VDDS_IDENT_H
#define VISCERA_VDDS_IDENT_H

#include <stddef.h>

#include <dds/dds.h>

/* Bound of the announced text and of what readers keep of a peer's
 * (room for a hostname and a certificate subject). */
#define VDDS_IDENT_MAX 512
/* Bound of a role name; longer ones are truncated. */
#define VDDS_ROLE_MAX 32

/* Sets this process's role ("server", "haptic", ...); NULL or "" means
 * "unknown". Non-printable characters and spaces become '_' so the role
 * stays one token. */
void vdds_set_role(const char *role);
/* The tool index this process drives, announced as tool=<n>; < 0: none. */
void vdds_set_tool(int tool);
const char *vdds_role(void);
/* The station (person or seat, idl ToolRole) this process acts for,
 * announced last as " station=<name>" (issue 16: a recording names who drove
 * each tool); NULL or "": none. A claim like the role. */
void vdds_set_station(const char *station);

/* Formats the announcement into out[cap] (always NUL-terminated, truncated
 * to fit); returns its length. Pure: host and pid are arguments. */
size_t vdds_ident_format(char *out, size_t cap, const char *role, int tool, const char *host, long pid);

/* This process's announcement (role, tool, gethostname, getpid). */
size_t vdds_ident_self(char *out, size_t cap);

/* A new participant QoS carrying vdds_ident_self() as USER_DATA; the caller
 * deletes it. NULL when out of memory. */
dds_qos_t *vdds_participant_qos(void);

/* Copies at most cap-1 bytes of untrusted `in[len]` into out, replacing
 * every byte outside 0x20..0x7e with '?', stopping at the first NUL; always
 * NUL-terminates (cap >= 1). Returns the length written. */
size_t vdds_ident_sanitize(char *out, size_t cap, const void *in, size_t len);

/* Extracts the role from a (sanitized) announcement: the value of the
 * "role=" token when the text starts with "viscera ", copied up to the next
 * space, bounded by cap. Returns 0, or -1 (out = "") when there is none. */
int vdds_ident_role(const char *ident, char *out, size_t cap);

#endif
