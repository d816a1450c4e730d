/* SPDX-License-Identifier: Apache-2.0 */
/* participants: who took part in a recorded session.
 *
 * Reads the DCPSParticipant built-in topic of the recorder's participant
 * and notes every participant of the domain in the store (table
 * participants, recording.h): its GUID, its USER_DATA (viscera processes
 * announce their role there, vdds_ident.h) bounded and sanitized to
 * printable text, the role parsed from it, and when it was first seen,
 * last seen and left (disposed, or its lease expired).
 *
 * Untrusted input: USER_DATA is cut at VDDS_IDENT_MAX and non-printable
 * bytes replaced; at most PARTICIPANTS_MAX distinct participants are
 * stored, so a flood of fake participants cannot grow the file without
 * bound (the overflow is counted and reported once on the log).
 * The role is a claim (see vdds_ident.h). When the recorder runs with DDS
 * Security, a participant's announced certificate subject is verified
 * against its authenticated GUID and stored (vdds_subject.h says what that
 * proves); without security no subject is stored. Not thread-safe. */
#ifndef VISCERA_REC_PARTICIPANTS_H
#define VISCERA_REC_PARTICIPANTS_H

#include <stdio.h>

#include <dds/dds.h>

#include "recording/store.h"
#include "verr.h"

#define PARTICIPANTS_MAX 1024

typedef struct participants participants_t;

int participants_open(participants_t **out, dds_entity_t participant, verr_t *err);
/* Takes every pending DCPSParticipant sample into the store. Returns -1
 * only when the store failed; DDS read errors go to `log`. */
int participants_poll(participants_t *p, store_t *store, FILE *log, verr_t *err);
/* Deletes the reader; NULL allowed. */
void participants_close(participants_t *p);

#endif
