/* viscera-haptic: a haptic-device client. Runs a 1 kHz loop that reads the
 * device, publishes ToolCommand and renders force from the latest
 * ContactFeedback's local contact model, coupled to the peer station's
 * device while the tool is guided (guide_force.h). Prints rate, jitter,
 * force, latency and guiding statistics on exit. */
#include <getopt.h>
#include <pthread.h>
#include <inttypes.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "contact_model.h"
#include "device.h"
#include "feedback_slot.h"
#include "guide_force.h"
#include "guide_report.h"
#include "guide_slot.h"
#include "vsignal.h"
#include "dds/vdds.h"
#include "viscera.h"
#include "vmath.h"
#include "vrt.h"
#include "vstats.h"
#include "vtime.h"

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int sig) {
  (void)sig;
  g_stop = 1;
}

static void usage(FILE *f) {
  fprintf(f,
          "usage: viscera-haptic --trajectory FILE [options]\n"
          "       viscera-haptic --device NAME [options]\n"
          "  --device NAME       scripted (default), dhd, hd or falcon; this build has: %s\n"
          "  --trajectory FILE   scripted device: play this path (t x y z [buttons] per line)\n"
          "  --device-index N    real devices: which one of that kind (default 0)\n"
          "  --workspace-scale S real devices: scene metres per device metre (default 1)\n"
          "  --workspace-offset X,Y,Z  real devices: scene position (m) of the device's\n"
          "                      workspace centre (default 0,0,0)\n"
          "  --tool N            tool index in the scene (default 0)\n"
          "  --station NAME      the station (person/seat) this device belongs to, announced with\n"
          "                      every command; a tool assigned to a station obeys only it\n"
          "                      (default: none, the anonymous station)\n"
          "  --domain N          DDS domain id (default: $VISCERA_DOMAIN or 0)\n"
          "  --partition P       session partition (default: " VDDS_DEFAULT_PARTITION ")\n"
          "  --rate HZ           loop rate (default 1000)\n"
          "  --max-force N       device capability in newtons (default 4)\n"
          "  --max-stiffness K   device stiffness rating, N/m: the server's contact stiffness is\n"
          "                      rendered clamped to it (default 0: no stated limit)\n"
          "  --wait-server S     wait up to S s for the server's scene before starting (default 10)\n"
          "  --duration S        stop after S s (default: end of the trajectory + 0.5 s)\n"
          "  --force-csv FILE    write t,x,y,z,fx,fy,fz,in_contact per tick\n"
          "  --rt-priority N     run the loop thread (only it) SCHED_FIFO at priority N (1..99) with\n"
          "                      memory locked (needs root, CAP_SYS_NICE or LimitRTPRIO; if refused:\n"
          "                      a warning naming the reason, normal priority)\n"
          "  --quiet             only the summary\n"
          "  --help              this text\n",
          device_names());
}

typedef struct stats {
  double *period_us;
  size_t nperiod, cap;
  double peak_force, force_sum;
  uint64_t ticks, contact_ticks, late_ticks;
} stats_t;

int main(int argc, char **argv) {
  vdds_set_role("haptic"); /* announced in the participant USER_DATA */
  const char *traj = NULL, *partition = NULL, *force_csv = NULL, *device = "scripted", *station = NULL;
  device_config_t dcfg;
  device_config_default(&dcfg);
  int domain = 0, quiet = 0, rt_priority = 0;
  unsigned tool = 0;
  double rate = 1000, max_force = 4, max_stiffness = 0, wait_server = 10, duration = -1;
  verr_t err;
  if ((domain = vdds_env_domain(&err)) < 0) {
    fprintf(stderr, "viscera-haptic: %s\n", err.msg);
    return 2;
  }
  static const struct option lo[] = {{"trajectory", required_argument, 0, 'j'},
                                     {"tool", required_argument, 0, 'n'},
                                     {"station", required_argument, 0, 's'},
                                     {"domain", required_argument, 0, 'd'},
                                     {"partition", required_argument, 0, 'p'},
                                     {"rate", required_argument, 0, 'r'},
                                     {"max-force", required_argument, 0, 'm'},
                                     {"max-stiffness", required_argument, 0, 'K'},
                                     {"wait-server", required_argument, 0, 'w'},
                                     {"duration", required_argument, 0, 't'},
                                     {"force-csv", required_argument, 0, 'f'},
                                     {"quiet", no_argument, 0, 'q'},
                                     {"rt-priority", required_argument, 0, 'R'},
                                     {"device", required_argument, 0, 'D'},
                                     {"device-index", required_argument, 0, 'I'},
                                     {"workspace-scale", required_argument, 0, 'S'},
                                     {"workspace-offset", required_argument, 0, 'O'},
                                     {"help", no_argument, 0, 'h'},
                                     {0, 0, 0, 0}};
  int c;
  while ((c = getopt_long(argc, argv, "j:n:s:d:p:r:m:K:w:t:f:R:D:I:S:O:qh", lo, NULL)) != -1) {
    char *end = NULL;
    double v = 0;
    if (c == 'r' || c == 'm' || c == 'K' || c == 'w' || c == 't' || c == 'n' || c == 'I' || c == 'S') {
      v = strtod(optarg, &end);
      if (*end || !isfinite(v) || v < 0) {
        fprintf(stderr, "viscera-haptic: option --%s: '%s' is not a non-negative number\n",
                c == 'r'   ? "rate"
                : c == 'm' ? "max-force"
                : c == 'K' ? "max-stiffness"
                : c == 'w' ? "wait-server"
                : c == 't' ? "duration"
                : c == 'I' ? "device-index"
                : c == 'S' ? "workspace-scale"
                           : "tool",
                optarg);
        return 2;
      }
    }
    switch (c) {
    case 'j':
      traj = optarg;
      break;
    case 'n':
      tool = (unsigned)v;
      break;
    case 's':
      if (!vdds_station_valid(optarg)) {
        fprintf(stderr, "viscera-haptic: --station '%s': 1..%d characters of A-Z a-z 0-9 _ . -\n", optarg,
                VDDS_STATION_MAX - 1);
        return 2;
      }
      station = optarg;
      break;
    case 'd':
      if ((domain = vdds_parse_domain(optarg)) < 0) {
        fprintf(stderr, "viscera-haptic: --domain '%s' is not a domain id 0..230\n", optarg);
        return 2;
      }
      break;
    case 'p':
      partition = optarg;
      break;
    case 'r':
      rate = v;
      break;
    case 'm':
      max_force = v;
      break;
    case 'K':
      max_stiffness = v;
      break;
    case 'w':
      wait_server = v;
      break;
    case 't':
      duration = v;
      break;
    case 'f':
      force_csv = optarg;
      break;
    case 'R':
      if (vrt_parse_priority(optarg, &rt_priority)) {
        fprintf(stderr, "viscera-haptic: --rt-priority '%s' is not a SCHED_FIFO priority 1..99\n", optarg);
        return 2;
      }
      break;
    case 'D':
      device = optarg;
      break;
    case 'I':
      if (v != floor(v) || v > 15) {
        fprintf(stderr, "viscera-haptic: --device-index must be an integer 0..15\n");
        return 2;
      }
      dcfg.index = (int)v;
      break;
    case 'S':
      if (!(v > 0) || v > 1000) {
        fprintf(stderr, "viscera-haptic: --workspace-scale must be > 0 and <= 1000\n");
        return 2;
      }
      dcfg.scale = v;
      break;
    case 'O': {
      double o[3];
      char tail = 0;
      if (sscanf(optarg, "%lf,%lf,%lf%c", &o[0], &o[1], &o[2], &tail) != 3 || !isfinite(o[0]) || !isfinite(o[1]) ||
          !isfinite(o[2]) || fabs(o[0]) > 100 || fabs(o[1]) > 100 || fabs(o[2]) > 100) {
        fprintf(stderr, "viscera-haptic: --workspace-offset '%s': expected X,Y,Z in metres (|value| <= 100)\n", optarg);
        return 2;
      }
      memcpy(dcfg.offset, o, sizeof o);
      break;
    }
    case 'q':
      quiet = 1;
      break;
    case 'h':
      usage(stdout);
      return 0;
    default:
      usage(stderr);
      return 2;
    }
  }
  if (!traj && strcmp(device, "scripted") == 0) {
    fprintf(stderr,
            "viscera-haptic: --trajectory FILE is required for the scripted device (or choose --device: "
            "this build has %s)\n",
            device_names());
    return 2;
  }
  if (!(rate >= 10 && rate <= 10000) || !(max_force > 0)) {
    fprintf(stderr, "viscera-haptic: --rate must be 10..10000 Hz and --max-force > 0\n");
    return 2;
  }
  device_t dev;
  dcfg.trajectory = traj;
  dcfg.max_force = max_force;
  dcfg.max_stiffness = max_stiffness;
  if (device_open(&dev, device, &dcfg, &err)) {
    fprintf(stderr, "viscera-haptic: %s\n", err.msg);
    return 1;
  }
  vdds_t dds;
  vdds_set_tool((int)tool);
  if (vdds_open(&dds, domain, partition, &err)) {
    fprintf(stderr, "viscera-haptic: %s\n", err.msg);
    dev.ops->close(&dev);
    return 1;
  }
  dds_entity_t w_cmd = vdds_writer_station(&dds, VT_TOOL_COMMAND, station, &err);
  static feedback_slot_t slot;
  double cap_s = duration >= 0 ? duration + 1 : 600;
  if (feedback_slot_init(&slot, tool, (size_t)fmin(1e7, fmax(1000, rate * cap_s)))) {
    fprintf(stderr, "viscera-haptic: out of memory\n");
    return 1;
  }
  dds_entity_t r_fb = feedback_slot_attach(&slot, &dds, &err);
  dds_entity_t r_scene = vdds_reader(&dds, VT_SCENE_INFO, &err);
  /* Guiding hand: the tool's role and the other station's positions. */
  static guide_slot_t guide;
  if (guide_slot_init(&guide, tool)) {
    fprintf(stderr, "viscera-haptic: cannot initialise the guide slot\n");
    return 1;
  }
  if (w_cmd < 0 || r_fb < 0 || r_scene < 0 || guide_slot_attach(&guide, &dds, w_cmd, &err)) {
    fprintf(stderr, "viscera-haptic: %s\n", err.msg);
    return 1;
  }
  vsignal_on_stop(on_signal, 0);

  /* Wait for the scene so the script starts when the server can answer. */
  uint64_t wait_until = vtime_mono_ns() + (uint64_t)(wait_server * 1e9);
  int have_scene = 0;
  while (!g_stop && vtime_mono_ns() < wait_until) {
    void *samples[1] = {0};
    dds_sample_info_t info;
    int n = dds_take(r_scene, samples, &info, 1, 1);
    if (n > 0) {
      const viscera_SceneInfo *si = samples[0];
      if (info.valid_data) {
        have_scene = 1;
        if (!quiet)
          fprintf(stderr, "haptic: scene '%s', %u tool(s); driving tool %u\n", si->scene, si->tools._length, tool);
        if (tool >= si->tools._length)
          fprintf(stderr, "haptic: warning: tool %u is not in the scene; the server will reject its commands\n", tool);
      }
      dds_return_loan(r_scene, samples, n);
      if (have_scene) break;
    }
    dds_sleepfor(DDS_MSECS(5));
  }
  if (!have_scene && !g_stop) {
    fprintf(stderr, "viscera-haptic: no server answered within %.1f s (domain %d, partition '%s')\n", wait_server,
            domain, partition ? partition : VDDS_DEFAULT_PARTITION);
    vdds_close(&dds);
    dev.ops->close(&dev);
    return 1;
  }

  FILE *csv = NULL;
  if (force_csv) {
    csv = fopen(force_csv, "w");
    if (!csv) {
      fprintf(stderr, "viscera-haptic: %s: cannot open for writing\n", force_csv);
      return 1;
    }
    fprintf(csv, "t,x,y,z,fx,fy,fz,in_contact\n");
  }

  /* A 1 kHz loop sharing two cores with physics and rendering misses its
   * tick whenever the scheduler prefers them; SCHED_FIFO and locked pages
   * keep the period. DDS threads stay at normal priority (vrt.h). */
  if (rt_priority) vrt_make_realtime(rt_priority, "haptic", "loop", quiet, stderr);
  uint64_t period_ns = (uint64_t)(1e9 / rate);
  stats_t st = {0};
  double run_for = duration >= 0 ? duration : 1e300;
  st.cap = (size_t)fmin(1e7, fmax(1000, rate * cap_s));
  st.period_us = malloc(st.cap * sizeof(double));
  if (!st.period_us) {
    fprintf(stderr, "viscera-haptic: out of memory\n");
    return 1;
  }
  contact_model_t model = {0};
  guide_report_t guide_rep;
  if (guide_report_init(&guide_rep, st.cap)) {
    fprintf(stderr, "viscera-haptic: out of memory\n");
    return 1;
  }
  const char *own_station = station ? station : "";
  double prev_pos[3] = {0, 0, 0};
  uint64_t prev_pos_ns = 0;
  int have_prev_pos = 0;
  uint64_t seq = 0;
  int server_lost_reported = 0;
  uint64_t live_lost_reported_ns = 0;
  uint64_t start = vtime_mono_ns(), next = start, prev_tick = 0;
  double finished_at = -1;
  while (!g_stop) {
    vtime_sleep_until(next);
    uint64_t now = vtime_mono_ns();
    double t = (double)(now - start) * 1e-9;
    if (prev_tick) {
      if (st.nperiod < st.cap) st.period_us[st.nperiod++] = (double)(now - prev_tick) * 1e-3;
      if (now > next + 1000000ull) st.late_ticks++; /* more than 1 ms late */
    }
    prev_tick = now;
    double pos[3], quat[4];
    uint32_t buttons = 0;
    dev.ops->read(&dev, t, pos, quat, &buttons);

    viscera_ToolCommand cmd;
    memset(&cmd, 0, sizeof cmd);
    cmd.tool_id = tool;
    cmd.seq = ++seq;
    cmd.client_mono_ns = now;
    for (int k = 0; k < 3; k++) cmd.position[k] = (float)pos[k];
    for (int k = 0; k < 4; k++) cmd.orientation[k] = (float)quat[k];
    cmd.buttons = buttons;
    cmd.max_force = (float)dev.max_force;
    feedback_slot_sent(&slot, cmd.seq, cmd.client_mono_ns); /* before the write: the echo may beat it back */
    dds_write(w_cmd, &cmd);

    uint64_t last_fb_mono = feedback_slot_read(&slot, &model);
    uint64_t lost_ns = 0, lost_last = 0;
    int lost_live = feedback_slot_server_lost(&slot, &lost_ns, &lost_last);
    if (last_fb_mono && server_lost_reported && !lost_live && now - last_fb_mono < 50000000ull) {
      fprintf(stderr, "haptic: server back\n");
      server_lost_reported = 0;
    }
    /* The server process is gone (its feedback writer's liveliness lapsed):
     * the listener already cleared the slot; say so once per loss, even when
     * the feedback timeout happened to notice first on a loaded machine. */
    if (lost_live) {
      model.in_contact = 0;
      if (lost_ns != live_lost_reported_ns) {
        live_lost_reported_ns = lost_ns;
        fprintf(stderr,
                "haptic: server lost (liveliness lost, last feedback %.0f ms before, lease %d ms), force set to "
                "zero\n",
                lost_last ? (double)(lost_ns - lost_last) * 1e-6 : -1.0, VDDS_FEEDBACK_LEASE_MS);
        server_lost_reported = 1;
      }
    }
    /* No feedback for 50 ms while the server is alive (stalled, or not
     * answering this tool): render nothing rather than a stale wall. */
    if (last_fb_mono && now > last_fb_mono + 50000000ull) {
      model.in_contact = 0;
      if (!server_lost_reported) {
        fprintf(stderr, "haptic: server lost (no feedback for 50 ms), force set to zero\n");
        server_lost_reported = 1;
      }
    }
    /* Device velocity by backward difference over the actual tick. */
    double vel[3] = {0, 0, 0};
    if (have_prev_pos && now > prev_pos_ns)
      for (int k = 0; k < 3; k++) vel[k] = (pos[k] - prev_pos[k]) / ((double)(now - prev_pos_ns) * 1e-9);
    memcpy(prev_pos, pos, sizeof prev_pos);
    prev_pos_ns = now;
    have_prev_pos = 1;
    /* Device capability data: never render a wall stiffer than the device
     * is rated for (its damping follows the clamped stiffness). */
    model.stiffness = contact_model_device_stiffness(model.stiffness, dev.max_stiffness);
    model.damping = contact_model_passive_damping(model.stiffness, 1.0 / rate);
    /* Guided or not, one force law (guide_force.h); a server silent for
     * GUIDE_SERVER_TIMEOUT_S ends the coupling too. */
    guide_view_t gv;
    guide_slot_read(&guide, own_station, now, &gv);
    guide_input_t gin = {.role = &gv.role,
                         .own_station = own_station,
                         .have_peer = gv.have_peer,
                         .peer_age_s = gv.peer_age_s,
                         .server_silent_s = !last_fb_mono        ? -1.0
                                            : now > last_fb_mono ? (double)(now - last_fb_mono) * 1e-9
                                                                 : 0.0,
                         .contact = &model,
                         .max_force = dev.max_force,
                         .max_stiffness = dev.max_stiffness,
                         .period_s = 1.0 / rate};
    memcpy(gin.x, pos, sizeof gin.x);
    memcpy(gin.v, vel, sizeof gin.v);
    memcpy(gin.peer, gv.peer, sizeof gin.peer);
    guide_output_t gout;
    guide_force(&gin, &gout);
    guide_report_tick(&guide_rep, t, &gv.role, gv.peer_station, gv.peer_age_s, &gout, quiet ? NULL : stderr);
    double *f = gout.f, mag = gout.magnitude;
    dev.ops->write_force(&dev, f);
    st.ticks++;
    /* In contact: the tissue pushes (a guiding spring in free space is not
     * contact; unguided, mag > 0 only in contact anyway). */
    if (mag > 0 && model.in_contact) {
      st.contact_ticks++;
      st.force_sum += mag;
    }
    if (mag > st.peak_force) st.peak_force = mag;
    if (csv)
      fprintf(csv, "%.4f,%.6f,%.6f,%.6f,%.5f,%.5f,%.5f,%d\n", t, pos[0], pos[1], pos[2], f[0], f[1], f[2],
              model.in_contact);

    if (t >= run_for) break;
    if (duration < 0 && dev.ops->finished(&dev, t)) {
      if (finished_at < 0) finished_at = t;
      if (t - finished_at > 0.5) break;
    }
    next += period_ns;
    if (now > next + 100000000ull) next = now; /* resynchronise after a long stall */
  }
  if (csv) fclose(csv);
  double elapsed = (double)(vtime_mono_ns() - start) * 1e-9;
  vstats_summary_t per = vstats_summarise(st.period_us, st.nperiod);
  pthread_mutex_lock(&slot.lock);
  vstats_summary_t lat = vstats_summarise(slot.latency_us, slot.nlatency);
  uint64_t feedback = slot.received, live_lost = slot.lost_events, live_back = slot.regained_events;
  uint64_t foreign = slot.foreign_echoes;
  pthread_mutex_unlock(&slot.lock);
  /* Jitter: the p99 of |period - nominal| (early and late ticks alike). */
  for (size_t i = 0; i < st.nperiod; i++) st.period_us[i] = fabs(st.period_us[i] - 1e6 / rate);
  vstats_summary_t jit = vstats_summarise(st.period_us, st.nperiod);
  double jitter_p99 = jit.p99;
  fprintf(stderr,
          "haptic: %" PRIu64 " ticks in %.2f s (%.1f Hz); period median %.1f us, p99 %.1f us, max %.1f us; "
          "%" PRIu64 " ticks over 1 ms late; jitter p99 %.1f us\n",
          st.ticks, elapsed, (double)st.ticks / elapsed, per.median, per.p99, per.max, st.late_ticks, jitter_p99);
  fprintf(stderr,
          "haptic: force peak %.3f N, mean in contact %.3f N, %" PRIu64 " ticks in contact, %" PRIu64
          " feedback samples\n",
          st.peak_force, st.contact_ticks ? st.force_sum / (double)st.contact_ticks : 0.0, st.contact_ticks, feedback);
  if (live_lost || live_back)
    fprintf(stderr, "haptic: server liveliness lost %" PRIu64 " time(s), regained %" PRIu64 " time(s)\n", live_lost,
            live_back);
  fprintf(stderr, "haptic: command->feedback latency median %.1f us, p99 %.1f us (%zu samples)\n", lat.median, lat.p99,
          lat.n);
  if (foreign)
    fprintf(stderr, "haptic: %" PRIu64 " feedback samples answered another station's commands (not in the latency)\n",
            foreign);
  guide_report_summary(&guide_rep, 1.0 / rate, stderr);
  pthread_mutex_lock(&guide.lock);
  fprintf(stderr,
          "haptic: guide: %" PRIu64 " ToolRole samples (%" PRIu64 " refused), %" PRIu64
          " commands from other stations (%" PRIu64 " not finite), %" PRIu64 " of ours skipped\n",
          guide.roles_received, guide.roles_rejected, guide.peer_samples, guide.bad_samples, guide.own_samples_skipped);
  pthread_mutex_unlock(&guide.lock);
  printf("SUMMARY ticks=%" PRIu64 " rate_hz=%.1f peak_force=%.4f contact_ticks=%" PRIu64 " latency_us_median=%.1f "
         "latency_us_p99=%.1f period_us_p99=%.1f jitter_us_p99=%.1f late_ticks=%" PRIu64 " guide_coupled_s=%.2f\n",
         st.ticks, (double)st.ticks / elapsed, st.peak_force, st.contact_ticks, lat.median, lat.p99, per.p99,
         jitter_p99, st.late_ticks, guide_report_coupled_s(&guide_rep, 1.0 / rate));
  free(st.period_us);
  guide_report_free(&guide_rep);
  vdds_close(&dds); /* stops the listener before the slot goes */
  feedback_slot_destroy(&slot);
  guide_slot_destroy(&guide);
  dev.ops->close(&dev);
  return 0;
}
