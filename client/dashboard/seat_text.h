/* SPDX-License-Identifier: Apache-2.0 */
/* seat_text: what the dashboard says about a seat, as plain functions of
 * plain data (no DDS, no drawing), so unit tests pin the wording and the
 * colours an instructor learns to read.
 *
 * Levels are the palpation thresholds of docs/methods.md B ch. 6: below ST, above ST
 * (the cue to ease off), above MPF (the most a palpation should use), above
 * SFT (the hard stop). Each has one colour everywhere on the dashboard:
 * threshold lines, tile alert frames, the focus view's level badge. */
#ifndef VISCERA_DASHBOARD_SEAT_TEXT_H
#define VISCERA_DASHBOARD_SEAT_TEXT_H

#include <stddef.h>

typedef enum seat_alert { SEAT_OK, SEAT_ABOVE_ST, SEAT_ABOVE_MPF, SEAT_ABOVE_SFT } seat_alert_t;

/* The highest level force f (N) is at or above; a threshold <= 0 (not set)
 * or a non-finite f counts as not reached. */
seat_alert_t seat_level_of(double f, float st, float mpf, float sft);
/* "ok", "ST", "MPF", "SFT" (dashboard.csv's alert column). */
const char *seat_level_name(seat_alert_t a);
/* sRGB 0..1: green below ST, amber above ST, red above MPF, magenta above SFT. */
void seat_level_rgb(seat_alert_t a, double rgb[3]);

/* Who drives a tool, from its ToolRole (idl): "any station", "owner alice",
 * "owner alice, guided by bob 50 %", "owner alice, taken over by bob" (authority
 * 1), "any station, guided by bob 30 %". have = 0 (no ToolRole received) reads
 * "any station": servers without roles let any station drive. Names are
 * untrusted and printed through seat_text_clean. Returns buf. */
char *seat_role_text(char *buf, size_t n, int have, const char *owner, const char *guide, double authority);

/* Copies src into dst (n > 0) keeping printable ASCII and turning anything
 * else into '?', so a sample's text cannot garble the display or the log. */
void seat_text_clean(char *dst, size_t n, const char *src);

/* The short label of a SessionEvent kind the focus view lists ("crossed up",
 * "client lost", "control", ...), or NULL for kinds it leaves out as noise
 * (contact begin/end, keyframes, topology changes) or does not know. */
const char *seat_event_label(int kind);

#endif
