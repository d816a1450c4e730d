/* SPDX-License-Identifier: Apache-2.0 */
/* guide_force: the force a haptic client renders while its tool is guided
 * ("guiding hand", idl/viscera.idl, the comment above ToolRole). Pure
 * arithmetic: no DDS, no clock, no allocation, so the 1 kHz loop can call it
 * and unit tests can check every branch.
 *
 * Roles: a ToolRole names the tool's owner station ("" = any station) and
 * its guide station ("" = not guided), the guide's authority a in 0..1 and
 * the coupling stiffness k. A client is on the guide side when its station
 * is the guide, on the owner side when it is the owner (or the owner is ""
 * and it is not the guide), otherwise on neither. Its own share is
 * w = a (guide side) or 1 - a (owner side), and the peer is the other side.
 *
 * Force law, for own position x and velocity v, the peer's latest commanded
 * position p and the tool position the server computes from the two,
 * x_tool = w x + (1 - w) p:
 *   F = w F_contact(x_tool, w v) + (1 - w) (k (p - x) - k (T + tau / 2) v)
 * - F_contact is the ContactFeedback plane model (contact_model.h), with the
 *   stiffness and damping the caller already set (device-clamped, passive at
 *   period T), re-anchored at the tool position of the command it answered
 *   when the caller gives its renderer (`render`, contact_render.h: the plain
 *   plane one round trip old overshoots, as for an unguided hand). The tool
 *   position is our prediction of the server's mix, with the peer's position
 *   as it reached us: off by (1 - w) times the way the peer moved in the
 *   difference between its path to us and to the server (none when both
 *   are equally far, or the peer is still). Its velocity is w v: the peer is taken as still within a tick,
 *   so the tool moves at w v. The hand then feels stiffness w^2 k_c and
 *   damping w^2 b_c, the same ratio that keeps the plain wall passive.
 * - The coupling spring (1 - w) k pulls the hand towards the peer. Its
 *   damping, on own velocity only (a differenced peer velocity would be
 *   noisy and one network delay old), is (1 - w) k (T + tau / 2): k T is
 *   twice the k T / 2 a zero-order-hold spring at period T generates
 *   (docs/numerics.md §6), and k tau / 2 for a round trip tau to the peer
 *   is the delay-dependent dissipation that keeps a spring between two
 *   delayed positions passive (Lee and Spong 2006, docs/remote.md): the
 *   guiding hand across sites.
 * - k is clamped to the device's stiffness rating, like the contact wall.
 * - The total is clamped to max_force (direction kept).
 * Fallbacks: no role, no guide, neither side, an invalid role (authority
 * outside 0..1, k not finite or <= 0), no peer position, or a peer position
 * older than GUIDE_PEER_TIMEOUT_S: plain contact rendering at own position,
 * as without roles (the server then uses our position alone too). A peer
 * still in the role but silent is therefore never a spring to a stale point.
 * Likewise no coupling once the server has been silent (no ContactFeedback)
 * for GUIDE_SERVER_TIMEOUT_S: the server is what makes the two hands one
 * tool, so a lost server ends the coupling as it ends the contact force. A
 * shorter gap (a feedback blip on a loaded machine: the contact force drops
 * for its 50 ms timeout) keeps the spring, so a guided hand is not jolted
 * by every blip. */
#ifndef VISCERA_GUIDE_FORCE_H
#define VISCERA_GUIDE_FORCE_H

#include <stdint.h>

#include "contact_model.h"
#include "contact_render.h"

#define GUIDE_STATION_MAX 32 /* = VDDS_STATION_MAX, with the terminating NUL */
#define GUIDE_PEER_TIMEOUT_S 0.1
#define GUIDE_SERVER_TIMEOUT_S 0.25
/* Largest coupling stiffness accepted from the wire, N/m (the scene's
 * largest tool stiffness); above it the role is refused as corrupt. */
#define GUIDE_MAX_COUPLING_STIFFNESS 1e5

typedef enum guide_side { GUIDE_SIDE_NONE, GUIDE_SIDE_OWNER, GUIDE_SIDE_GUIDE } guide_side_t;

/* The latest ToolRole of our tool, as plain data. */
typedef struct guide_role {
  int known; /* a ToolRole for the tool has arrived */
  uint32_t version;
  char owner[GUIDE_STATION_MAX];
  char guide[GUIDE_STATION_MAX];
  double authority;          /* 0..1 */
  double coupling_stiffness; /* N/m */
} guide_role_t;

/* 1 when the role's numbers are usable for coupling: a guide is named,
 * authority finite in 0..1, stiffness finite in (0, GUIDE_MAX_COUPLING_STIFFNESS]. */
int guide_role_valid(const guide_role_t *r);

/* Which side station `own` ("" = anonymous) is on; NONE when the role has
 * no guide or is invalid. */
guide_side_t guide_side_of(const guide_role_t *r, const char *own);

/* 1 when commands from `station` are the peer's for a client on `side`:
 * the guide's for the owner side; the owner's for the guide side (any
 * station but the guide's when the owner is ""). */
int guide_is_peer(const guide_role_t *r, guide_side_t side, const char *station);

/* Own share w of a client on `side` (1 for NONE). */
double guide_own_share(const guide_role_t *r, guide_side_t side);

typedef struct guide_input {
  const guide_role_t *role;
  const char *own_station; /* "" = anonymous */
  double x[3], v[3];       /* own device position (m) and velocity (m/s) */
  int have_peer;
  double peer[3];         /* peer's latest commanded position, m */
  double peer_age_s;      /* since it arrived */
  double server_silent_s; /* since the last ContactFeedback arrived; < 0: none yet */
  const contact_model_t *contact;
  double max_force;     /* N, > 0 */
  double max_stiffness; /* N/m device rating, 0 = none stated */
  double period_s;      /* loop period T */
  double rtt_s;         /* tau: round trip to the peer, s (0: same machine or LAN) */
  /* Coupled, the contact part re-anchored at the answered command
   * (contact_render_target at the tool) when set: the renderer's ring must
   * then hold, for each of our commands sent while coupled, the tool
   * position the server mixes for it, as we predict it (w x + (1 - w) p at
   * that tick: x_tool below). NULL: the plain plane at the tool. */
  contact_render_t *render;
} guide_input_t;

typedef struct guide_output {
  double f[3];
  double magnitude;
  int coupled;       /* 1 when the coupling law was rendered */
  guide_side_t side; /* our side per the role (even when not coupled) */
  double w;          /* own share used (1 when not coupled) */
  double k;          /* coupling stiffness used, N/m (0 when not coupled) */
  double x_tool[3];  /* where the contact force was evaluated */
  const char *why;   /* when not coupled: "no role", "no guide", "not in the role", "no peer",
                        "peer silent", "server silent"; NULL when coupled */
} guide_output_t;

/* Damping of the coupling spring on the hand's own velocity, N s/m: the
 * (1 - w) k (T + tau / 2) of the force law (0 when w = 1). */
double guide_coupling_damping(double w, double k, double period_s, double rtt_s);

/* Computes the force to render. Never returns a non-finite force: a
 * non-finite peer position counts as no peer. */
void guide_force(const guide_input_t *in, guide_output_t *out);

#endif
