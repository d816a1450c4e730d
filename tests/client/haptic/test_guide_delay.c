/* SPDX-License-Identifier: Apache-2.0 */
/* The guiding hand across sites (guide_force.c, issue 14 item 4): an
 * instructor's and a trainee's device coupled through guide_force, each
 * client at 1 kHz seeing the other's position one way later, with jitter
 * and loss, as DDS delivers a peer's ToolCommands (newest wins). Both hands
 * are simulated in process: the instructor's is driven by his arm (a
 * spring-damper to a reference path: out 3 cm, hold, back), the trainee's
 * is a relaxed hand (mass and light damping, no stiffness of its own).
 *
 * Checked per round trip (10, 50, 100, 200 ms, 5 % loss, authority 0.5):
 * the coupling network is passive (the energy it has delivered to the two
 * hands, sum of F . v dt over both ports, never above zero), no growing
 * oscillation (after the instructor stops, the hands' separation decays),
 * every force within the device maximum. The tracking error against delay
 * is printed. The same coupling without the delay-dependent damping
 * (tau = 0, the law before issue 14) is run at 200 ms: it must show what
 * the test catches. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "guide_force.h"
#include "test_rng.h"

#define T_S 0.001
#define SUB 10
#define DUR 6.0
#define MAX_F 6.0
#define NT 6000 /* DUR / T_S */

typedef struct hand {
  double m, b; /* kg, N s/m */
  double x, v;
} hand_t;

/* The instructor's reference: rest, out 3 cm (smoothstep, 0.6 s), hold,
 * back, rest. */
static double reference(double t) {
  double s;
  if (t < 0.5) return 0;
  if (t < 1.1) {
    s = (t - 0.5) / 0.6;
    return 0.03 * s * s * (3 - 2 * s);
  }
  if (t < 2.5) return 0.03;
  if (t < 3.1) {
    s = (t - 2.5) / 0.6;
    return 0.03 * (1 - s * s * (3 - 2 * s));
  }
  return 0;
}

typedef struct result {
  double energy_max, f_max, track_rms, sep_a, sep_b, sep_end;
} result_t;

static guide_role_t role(double a, double k) {
  guide_role_t r;
  memset(&r, 0, sizeof r);
  r.known = 1;
  snprintf(r.owner, sizeof r.owner, "alice");
  snprintf(r.guide, sizeof r.guide, "bob");
  r.authority = a;
  r.coupling_stiffness = k;
  return r;
}

/* One client's tick: force on its hand from guide_force. */
static void client_force(const guide_role_t *r, const char *own, const double x, const double v, double peer,
                         double peer_age, double rtt_est, double *f) {
  static const contact_model_t free_space = {0};
  guide_input_t in;
  memset(&in, 0, sizeof in);
  in.role = r;
  in.own_station = own;
  in.x[0] = x;
  in.v[0] = v;
  in.have_peer = 1;
  in.peer[0] = peer;
  in.peer_age_s = peer_age;
  in.server_silent_s = 0.001;
  in.contact = &free_space;
  in.max_force = MAX_F;
  in.period_s = T_S;
  in.rtt_s = rtt_est;
  guide_output_t o;
  guide_force(&in, &o);
  *f = o.f[0];
}

static void run(int rtt_ms, double loss, double rtt_est, uint64_t seed, result_t *res) {
  guide_role_t r = role(0.5, 200);
  hand_t tr = {.m = 0.3, .b = 1.0}, in = {.m = 0.3, .b = 0.0};
  const double kh = 200, bh = 8; /* the instructor's arm */
  /* Positions sent each tick and when each arrives at the other side. */
  static double sent_t[NT], sent_i[NT];
  static int arr_t[NT], arr_i[NT];
  uint64_t rng = seed;
  int last_t = 0, last_i = 0, d = rtt_ms / 2;
  for (int j = 0; j < NT; j++) {
    int a = j + d + (int)lround((test_rng_uniform(&rng) - 0.5) * 0.4 * d);
    int b = j + d + (int)lround((test_rng_uniform(&rng) - 0.5) * 0.4 * d);
    if (a < last_t) a = last_t;
    if (b < last_i) b = last_i;
    last_t = a;
    last_i = b;
    arr_t[j] = test_rng_uniform(&rng) < loss ? -1 : a;
    arr_i[j] = test_rng_uniform(&rng) < loss ? -1 : b;
  }
  memset(res, 0, sizeof *res);
  double energy = 0, px_t = 0, px_i = 0, sq = 0;
  int nsq = 0, have_t = 0, have_i = 0, got_t = -1, got_i = -1, next_t = 0, next_i = 0;
  double peer_of_t = 0, peer_of_i = 0; /* what each side holds of the other */
  for (int j = 0; j < NT; j++) {
    double t = j * T_S;
    sent_t[j] = tr.x;
    sent_i[j] = in.x;
    /* Arrivals up to now (in order; newest wins). */
    while (next_i < NT && next_i <= j && (arr_i[next_i] < 0 || arr_i[next_i] <= j)) {
      if (arr_i[next_i] >= 0) {
        peer_of_t = sent_i[next_i];
        got_t = j;
        have_t = 1;
      }
      next_i++;
    }
    while (next_t < NT && next_t <= j && (arr_t[next_t] < 0 || arr_t[next_t] <= j)) {
      if (arr_t[next_t] >= 0) {
        peer_of_i = sent_t[next_t];
        got_i = j;
        have_i = 1;
      }
      next_t++;
    }
    /* Each client's velocity by backward difference, as the loop does. */
    double v_t = j ? (tr.x - px_t) / T_S : 0, v_i = j ? (in.x - px_i) / T_S : 0;
    px_t = tr.x;
    px_i = in.x;
    double f_t = 0, f_i = 0;
    if (have_t) client_force(&r, "alice", tr.x, v_t, peer_of_t, (j - got_t) * T_S, rtt_est, &f_t);
    if (have_i) client_force(&r, "bob", in.x, v_i, peer_of_i, (j - got_i) * T_S, rtt_est, &f_i);
    if (fabs(f_t) > res->f_max) res->f_max = fabs(f_t);
    if (fabs(f_i) > res->f_max) res->f_max = fabs(f_i);
    for (int k = 0; k < SUB; k++) {
      double h = T_S / SUB, ref = reference(t + k * h);
      double a_t = (f_t - tr.b * tr.v) / tr.m;
      double a_i = (f_i + kh * (ref - in.x) - bh * in.v) / in.m;
      tr.v += a_t * h;
      in.v += a_i * h;
      tr.x += tr.v * h;
      in.x += in.v * h;
      /* The network's power into the hands (the coupling's forces only). */
      energy += (f_t * tr.v + f_i * in.v) * h;
    }
    if (energy > res->energy_max) res->energy_max = energy;
    double sep = fabs(tr.x - in.x);
    if (t > 0.5 && t < 3.1) {
      sq += sep * sep;
      nsq++;
    }
    if (t > 3.6 && t < 4.6 && sep > res->sep_a) res->sep_a = sep;
    if (t > 4.6 && t < 5.6 && sep > res->sep_b) res->sep_b = sep;
    if (!isfinite(tr.x) || !isfinite(in.x)) break;
  }
  res->track_rms = sqrt(sq / (nsq ? nsq : 1));
  res->sep_end = fabs(tr.x - in.x);
}

int main(void) {
  const int rtts[] = {10, 50, 100, 200};
  printf("%9s %6s %12s %8s %14s %16s %16s\n", "round trip", "loss", "energy J", "max |F|", "tracking rms mm",
         "sep 0.5-1.5 s mm", "sep 1.5-2.5 s mm");
  for (int i = 0; i < 4; i++) {
    result_t res;
    run(rtts[i], 0.05, rtts[i] * 1e-3, 11 + (uint64_t)i, &res);
    printf("%6d ms %5.0f%% %12.3g %8.3f %14.2f %16.3f %16.3f\n", rtts[i], 5.0, res.energy_max, res.f_max,
           res.track_rms * 1e3, res.sep_a * 1e3, res.sep_b * 1e3);
    CHECK(res.energy_max <= 1e-6);                    /* passive: the network never gave energy */
    CHECK(res.f_max <= MAX_F + 1e-9);                 /* within the device maximum */
    CHECK(res.sep_b <= res.sep_a + 1e-4);             /* no growing oscillation */
    CHECK(res.sep_end < 0.002);                       /* the hands meet again */
    CHECK(res.track_rms > 0 && res.track_rms < 0.03); /* the trainee follows */
  }
  /* Without the delay-dependent damping: not passive at 200 ms. */
  result_t old;
  run(200, 0.05, 0.0, 11, &old);
  printf("200 ms without tau damping: energy %.3g J, max |F| %.3f N, separation %.3f then %.3f mm\n", old.energy_max,
         old.f_max, old.sep_a * 1e3, old.sep_b * 1e3);
  CHECK(old.energy_max > 1e-4 || old.sep_b > old.sep_a);
  return check_report("test_guide_delay");
}
