/* SPDX-License-Identifier: Apache-2.0 */
/* docs/numerics.md §5 cases 9 and 16, the haptic extremes.
 *
 * 9: on the default kidney scene, a one-step load of 1000 g on every node
 *    and then the probe commanded 10 cm inside the organ: everything stays
 *    finite, the proxy stays on the entry surface, the force is clamped to
 *    the device maximum, and the organ returns to rest afterwards.
 * 16: the haptic client's local contact model against a 1 N/mm wall, 60 s of
 *    scripted motion at 1 kHz with tick jitter and a 2 ms old plane, watched
 *    by a passivity observer: the energy the device puts into the hand,
 *    sum F . dx, never ends a contact episode above zero. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_runtime.h"
#include "contact_model.h"
#include "runtime/scene_runtime.h"
#include "vmath.h"

static double rnd(unsigned *s) {
  *s = *s * 1664525u + 1013904223u;
  return (double)(*s >> 8) / 16777216.0;
}

static double max_rest_error(const runtime_t *rt) {
  const model_t *m = rt->organs[0].model;
  double e = 0;
  for (size_t i = 0; i < 3 * m->nsurf; i++) e = fmax(e, fabs(m->surf_x[i] - m->surf_rest[i]));
  return e;
}

static int all_finite(const runtime_t *rt) {
  const model_t *m = rt->organs[0].model;
  for (size_t i = 0; i < 3 * m->nnodes; i++)
    if (!isfinite(m->x[i]) || !isfinite(m->v[i])) return 0;
  return 1;
}

static void big_load(model_t *m, void *ctx) {
  int *armed = ctx;
  if (!*armed) return;
  /* 1000 g on every surface node for one sub-step's worth of the step. */
  double per_node = 0.15 / (double)m->nsurf * 1000 * 9.81;
  for (uint32_t i = 0; i < m->nsurf; i++) m->ops->add_surface_force(m, i, (double[]){per_node * 0.3, 0, -per_node});
}

static void case9(void) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  if (!src) {
    CHECK(!"VISCERA_SOURCE_DIR set");
    return;
  }
  static scene_t sc;
  static runtime_t rt;
  if (!test_runtime_load_scene(&rt, &sc, "default.yaml", NULL)) {
    CHECK(!"default scene loads");
    return;
  }
  model_t *m = rt.organs[0].model;
  /* One step under 1000 g, through the same hook contact uses. */
  void (*hook)(model_t *, void *) = m->hook;
  void *hook_ctx = m->hook_ctx;
  int armed = 1;
  m->hook = big_load;
  m->hook_ctx = &armed;
  runtime_step(&rt);
  armed = 0;
  m->hook = hook;
  m->hook_ctx = hook_ctx;
  CHECK(all_finite(&rt));
  printf("case 9: after one 1000 g step the surface is off rest by %.3g m\n", max_rest_error(&rt));
  for (int s = 0; s < 3000; s++) runtime_step(&rt);
  double rest_err = max_rest_error(&rt);
  printf("case 9: 3 s later off rest by %.3g m\n", rest_err);
  CHECK(all_finite(&rt) && rest_err < 1e-4);

  /* Probe from above to 10 cm below the top, through the whole organ. */
  double top[3] = {0.012, 0.004, 0.07};
  double peak = 0, min_proxy_z = INFINITY;
  int contact_all_way = 1;
  for (int s = 0; s < 2000; s++) {
    double p[3] = {top[0], top[1], top[2] - fmin(1.0, s / 1000.0) * (0.0346 + 0.1 - 0.035 + 0.035)};
    runtime_set_tool(&rt, 0, p, 4.0);
    runtime_step(&rt);
    const tool_rt_t *t = &rt.tools[0];
    if (p[2] < 0.03) {
      contact_all_way = contact_all_way && t->proxy.in_contact;
      min_proxy_z = fmin(min_proxy_z, t->proxy.pos[2]);
      peak = fmax(peak, v3_norm(t->force));
    }
  }
  const tool_rt_t *t = &rt.tools[0];
  printf("case 9: device at z = %.3f m, proxy at z = %.4f m (lowest %.4f), force %.3f N (peak %.3f, clamp 4)\n",
         t->cmd.pos[2], t->proxy.pos[2], min_proxy_z, v3_norm(t->force), peak);
  CHECK(contact_all_way);
  CHECK(min_proxy_z > 0.0); /* never through to the far side (the kidney spans z 0..0.035) */
  CHECK(peak <= 4.0 + 1e-9 && peak > 3.99);
  CHECK(all_finite(&rt));
  /* Withdraw and let the organ recover. */
  for (int s = 0; s < 4000; s++) {
    double p[3] = {top[0], top[1], 0.1};
    runtime_set_tool(&rt, 0, p, 4.0);
    runtime_step(&rt);
  }
  rest_err = max_rest_error(&rt);
  printf("case 9: after withdrawal off rest by %.3g m, contact %d\n", rest_err, rt.tools[0].proxy.in_contact);
  CHECK(rt.tools[0].proxy.in_contact == 0 && rest_err < 1e-4);
  runtime_destroy(&rt);
}

/* Runs the 60 s script against the wall with the given damping; returns the
 * net energy into the hand and the worst contact episode's. */
static int run_wall(double damping, double *net, double *worst) {
  const double k = 1000.0, T = 1e-3, max_force = 40.0;
  contact_model_t wall = {.in_contact = 1, .normal = {0, 0, 1}, .stiffness = k, .damping = damping};
  unsigned seed = 42;
  /* The script starts 1 mm above the wall at rest, at (0, 0.01). */
  double x[3] = {0, 0.01, 0.001}, xprev[3], t = 0, energy = 0, worst_episode = -INFINITY, ep_energy = 0;
  double hist[8][3]; /* device positions of the last ticks: the plane is 2 ms old */
  for (int i = 0; i < 8; i++) v3_copy(hist[i], x);
  int in = 0, episodes = 0;
  double Fprev[3] = {0, 0, 0}, posprev[3] = {0, 0.01, 0.001};
  long ticks = 0;
  v3_copy(xprev, x);
  while (t < 60.0) {
    double dt = T * (1 + 0.1 * (rnd(&seed) - 0.5)); /* jitter +-5 % */
    t += dt;
    /* Scripted hand: presses up to 3 mm in at a frequency sweeping 0.5-5 Hz,
     * with a little tremor, sliding sideways. */
    double f = 0.5 + 4.5 * (0.5 + 0.5 * sin(0.05 * t));
    /* Physiological tremor (8-12 Hz, 20 um): smooth, as a hand is; white
     * position noise at 1 kHz would be a hand no motor could follow. */
    double z = 0.001 - 0.004 * (0.5 - 0.5 * cos(2 * M_PI * f * t)) + 2e-5 * sin(2 * M_PI * (10 + 2 * sin(t)) * t);
    double pos[3] = {0.01 * sin(0.3 * t), 0.01 * cos(0.2 * t), z};
    /* The server's proxy for the flat wall z = 0: the device 2 ms ago projected on it. */
    const double *old = hist[ticks % 8 >= 2 ? (ticks - 2) % 8 : 0];
    wall.proxy[0] = old[0];
    wall.proxy[1] = old[1];
    wall.proxy[2] = 0;
    double v[3];
    for (int c = 0; c < 3; c++) v[c] = (pos[c] - xprev[c]) / dt;
    double F[3];
    contact_model_force(&wall, pos, v, max_force, F);
    /* Zero-order hold: F acts on the hand until the next tick. */
    v3_copy(xprev, pos);
    v3_copy(hist[ticks % 8], pos);
    ticks++;
    /* Work done by the device on the hand over this tick: F . (x_next - x);
     * accumulated at the next tick, when x_next is known. */
    double dx[3];
    v3_sub(dx, pos, posprev);
    double w = v3_dot(Fprev, dx);
    energy += w;
    ep_energy += w;
    v3_copy(Fprev, F);
    v3_copy(posprev, pos);
    int now_in = z < 0;
    if (in && !now_in) { /* episode ends: the hand left the wall */
      worst_episode = fmax(worst_episode, ep_energy);
      episodes++;
      ep_energy = 0;
    }
    in = now_in;
  }
  printf("case 16: damping %.2g N s/m: %ld ticks, %d contact episodes, net energy into the hand %.3g J, worst "
         "episode %.3g J\n",
         damping, ticks, episodes, energy, worst_episode);
  *net = energy;
  *worst = worst_episode;
  return episodes;
}

static void case16(void) {
  double net, worst;
  /* The client's damping (k T for 1 kHz): passive. */
  int episodes = run_wall(contact_model_passive_damping(1000.0, 1e-3), &net, &worst);
  CHECK(episodes > 50);
  CHECK(net <= 0);
  CHECK(worst <= 1e-12);
  /* Without it the sampled wall is active, and the observer must see so. */
  run_wall(0.0, &net, &worst);
  CHECK(worst > 0);
}

int main(void) {
  case9();
  case16();
  return check_report("stab_haptic");
}
