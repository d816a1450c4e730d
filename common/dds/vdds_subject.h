/* SPDX-License-Identifier: Apache-2.0 */
/* vdds_subject: the certificate subject of a participant, when DDS
 * Security is on (issue 16: a recording names who trained).
 *
 * What is verified, and by whom. Cyclone DDS 0.10.2 exposes no
 * authenticated peer identity through its API. But its authentication
 * plugin (DDS:Auth:PKI-DH) binds the participant's GUID to its certificate:
 * the first 47 bits of the GUID prefix are the SHA-256 of the certificate's
 * subject (DER), behind a 1 bit (the adjusted GUID of DDS Security 9.3.3),
 * and during the handshake the plugin checks that the peer's participant
 * data carries exactly that GUID for the certificate it verified against
 * the identity CA ("c.pdata contains incorrect participant guid" refuses
 * it). A secure process therefore announces its subject (DER, hex) in its
 * USER_DATA (vdds_ident.h, token "cert="), and a secure reader accepts the
 * announcement only when it hashes to the GUID it authenticated: a peer
 * cannot name a subject other than its own certificate's (up to a 47-bit
 * hash collision). Without security the GUID is chosen freely, so readers
 * keep no subject at all.
 *
 * Untrusted input: the hex is bounded (VDDS_SUBJECT_DER_MAX) and parsed by
 * OpenSSL's DER decoder; the text is printable ASCII only. No global state
 * except the cached own subject (set once, from main's thread). */
#ifndef VISCERA_VDDS_SUBJECT_H
#define VISCERA_VDDS_SUBJECT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* A subject's DER, and its text (RFC 2253, as deploy/pki.sh's permissions
 * name it: "CN=trainee-seat01,O=viscera,C=NL"). */
#define VDDS_SUBJECT_DER_MAX 160
#define VDDS_SUBJECT_TEXT_MAX 160

/* This process's subject: the DER subject of the identity certificate the
 * configuration in CYCLONEDDS_URI names (<IdentityCertificate>file:PATH or
 * data:,PEM, in a file:// element or inline). Returns its length, 0 when
 * security is off or the certificate cannot be read. Cached after the
 * first call. */
size_t vdds_subject_self(uint8_t der[VDDS_SUBJECT_DER_MAX]);

/* true when the first 47 bits of guid's prefix are those Cyclone's
 * authentication plugin derives from this DER subject. */
bool vdds_subject_matches_guid(const uint8_t guid[16], const uint8_t *der, size_t len);

/* The DER subject as RFC 2253 text into out (printable ASCII, bounded);
 * returns 0, or -1 when it is not a valid X.509 name. */
int vdds_subject_text(const uint8_t *der, size_t len, char *out, size_t cap);

/* Outcome of vdds_subject_verify. */
enum { VDDS_SUBJECT_NONE = 0, VDDS_SUBJECT_VERIFIED = 1, VDDS_SUBJECT_MISMATCH = -1 };
/* Reads the "cert=" token of an announcement (vdds_ident.h) and accepts it
 * when it is a valid name that matches guid: VERIFIED with the text in out;
 * NONE without a token; MISMATCH (out = "") when it is malformed or names
 * another certificate than the one the GUID was derived from. */
int vdds_subject_verify(const char *ident, const uint8_t guid[16], char *out, size_t cap);

#endif
