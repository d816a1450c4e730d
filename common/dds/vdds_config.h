/* SPDX-License-Identifier: Apache-2.0 */
/* vdds_config: the Cyclone DDS configuration every viscera process uses, and
 * the explanation a client prints when it sees nothing.
 *
 * One default everywhere: a process started without CYCLONEDDS_URI uses the
 * loopback configuration (deploy/cyclonedds-loopback.xml, found through
 * data_path.h: $VISCERA_DATA_DIR, the installed share/viscera, the source
 * tree), exactly as the scripts in deploy/ do, and the domain is
 * $VISCERA_DOMAIN or 0 (common/cli.c). So commands pasted from the README or
 * from deploy/lab.sh's start lines meet in the same domain on the same
 * interface.
 *
 * "Nothing seen": a client that has matched no peer after
 * VDDS_NOTHING_SEEN_S prints, once, what it is listening to (domain,
 * partition, configuration, security on or off) and the likely causes: no
 * server there, or secure peers that refuse a participant without an
 * identity (or with one their permissions do not cover). The messages are
 * listed in the README's troubleshooting section.
 * Not thread-safe: call from main's thread before creating participants. */
#ifndef VISCERA_VDDS_CONFIG_H
#define VISCERA_VDDS_CONFIG_H

#include <dds/dds.h>
#include <stdint.h>
#include <stdio.h>

#include "verr.h"

#define VDDS_LOOPBACK_CONFIG "deploy/cyclonedds-loopback.xml"
#define VDDS_NOTHING_SEEN_S 5.0

/* Sets CYCLONEDDS_URI to file://<loopback configuration> when it is unset
 * or empty. Returns 0 (set now or already set), -1 when it was unset and
 * the file is nowhere (Cyclone's own defaults then apply). Idempotent. */
int vdds_config_default(void);

/* 1 when the configuration in CYCLONEDDS_URI turns DDS Security on (a
 * <Security>/<DDSSecurity> section inline or in a file:// element), else 0. */
int vdds_config_secure(void);

/* 1 when every file:// element of CYCLONEDDS_URI is the loopback
 * configuration (VDDS_LOOPBACK_CONFIG: nothing leaves the machine) and
 * nothing else is inline; 0 otherwise (unset counts as loopback: the
 * default, vdds_config_default). */
int vdds_config_loopback(void);

/* Off loopback, secure by default (issue 14). When the configuration is
 * neither loopback nor secure, a program refuses to start unless told the
 * choice is intended: --insecure (common/cli.c, every DDS program) or
 * $VISCERA_INSECURE=1 (which --insecure sets; deploy/net_guard.sh honours
 * the same). Returns 0 when the process may go on: loopback, secure, or
 * allowed, in which case a warning naming the configuration is written to
 * f (once per process: the caller keeps `warned`, NULL: always). Returns -1
 * with err naming the configuration and the ways on otherwise; when a file://
 * element cannot be read (an identity's fragment by a relative path from
 * another directory), err names that file and the current directory instead. */
int vdds_config_check_insecure(FILE *f, const char *tag, int *warned, verr_t *err);

/* What every DDS participant of viscera is created after: the default
 * configuration (vdds_config_default), then vdds_config_check_insecure.
 * 0 to go on, -1 with err (refused). */
int vdds_config_prepare(FILE *f, const char *tag, verr_t *err);

/* Publications (writers) matched by `reader` now; 0 on error. */
int vdds_matched_writers(dds_entity_t reader);
/* Subscriptions (readers) matched by `writer` now; 0 on error. */
int vdds_matched_readers(dds_entity_t writer);

/* 1 (once: *reported is set) when `matched` peers is still 0
 * VDDS_NOTHING_SEEN_S after start_ns (monotonic ns, like now_ns). */
int vdds_nothing_seen_due(int *reported, int matched, uint64_t start_ns, uint64_t now_ns);

/* Prints the "nothing seen" explanation, every line prefixed "TAG: ":
 *   TAG: nothing seen after 5 s: WHAT
 *   TAG:   listening on domain D, partition 'P'
 *   TAG:   configuration: <CYCLONEDDS_URI>, DDS Security off|on
 *   TAG:   likely cause: ...
 * `what` says what was expected ("no server in this partition"). */
void vdds_explain_nothing_seen(FILE *f, const char *tag, const char *what, int domain, const char *partition,
                               double waited_s);

#endif
