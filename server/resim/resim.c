/* viscera-resim: deterministic re-simulation of a recorded session.
 *
 * Feeds the recorded ToolCommands, step by step as the server applied them
 * (schedule rebuilt from the recorded ContactFeedback, resim_schedule.h),
 * into a fresh runtime of the scene and compares every recorded mesh frame
 * with the re-simulated surface (resim_run.h). Exit 0 when every organ's
 * largest per-coordinate error is within the tolerance, 1 beyond it, 2 on
 * a usage error, an unreadable recording or a scene that is not the
 * recorded one. No DDS: runs anywhere the recording is. */
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "resim/resim_recording.h"
#include "resim/resim_run.h"
#include "scene.h"
#include "runtime/scene_runtime.h"
#include "vtime.h"

/* Float rounding of a recorded position (keyframe float plus quantized
 * delta, |x| < 1 m): a few 1e-9 m. The default tolerance adds this to the
 * quantization bound quant_step / 2. */
#define RESIM_FLOAT_SLACK 5e-8

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-resim --scene SCENE.yaml REC.db [options]\n"
             "  --scene FILE      the scene the session ran (must match the recording's SceneInfo)\n"
             "  --tolerance M     largest per-coordinate error allowed, m (default: quant_step/2 + 5e-8)\n"
             "  --csv FILE        one line per compared frame: step,sim_time_s,organ,kind,max_err_m,rms_err_m,exact\n"
             "  --quiet           no progress lines\n"
             "  --help            this text\n"
             "Re-runs the recorded tool commands in a fresh server runtime and compares every recorded\n"
             "MeshState/MeshDelta frame. Exit 0 within tolerance, 1 beyond, 2 on an error.\n");
}

typedef struct cli_ctx {
  FILE *csv;
  double dt;
  int quiet;
  uint64_t t0, last_print;
} cli_ctx_t;

static void on_frame(void *arg, uint64_t step, uint32_t organ, int keyframe, double max_err, double rms, int exact) {
  cli_ctx_t *c = arg;
  if (c->csv)
    fprintf(c->csv, "%" PRIu64 ",%.6f,%u,%s,%.9g,%.9g,%d\n", step, (double)step * c->dt, organ,
            keyframe ? "keyframe" : "delta", max_err, rms, exact);
}

static void on_progress(void *arg, uint64_t step, uint64_t total) {
  cli_ctx_t *c = arg;
  uint64_t now = vtime_mono_ns();
  /* A line every 2 s of wall time, so long recordings show they move. */
  if (c->quiet || now - c->last_print < 2000000000ull || step == 0) return;
  c->last_print = now;
  double el = (double)(now - c->t0) * 1e-9;
  fprintf(stderr, "resim: step %" PRIu64 " / %" PRIu64 " (%.0f %%), %.1f s elapsed, %.1f s left\n", step, total,
          100.0 * (double)step / (double)total, el, el * (double)(total - step) / (double)step);
}

int main(int argc, char **argv) {
  const char *scene_path = NULL, *csv_path = NULL;
  double tolerance = -1;
  int quiet = 0;
  static const struct option lo[] = {{"scene", required_argument, 0, 's'}, {"tolerance", required_argument, 0, 't'},
                                     {"csv", required_argument, 0, 'c'},   {"quiet", no_argument, 0, 'q'},
                                     {"help", no_argument, 0, 'h'},        {0, 0, 0, 0}};
  int o;
  while ((o = getopt_long(argc, argv, "s:t:c:qh", lo, NULL)) != -1) {
    char *end = NULL;
    switch (o) {
    case 's':
      scene_path = optarg;
      break;
    case 'c':
      csv_path = optarg;
      break;
    case 'q':
      quiet = 1;
      break;
    case 't':
      tolerance = strtod(optarg, &end);
      if (!end || *end || !(tolerance >= 0) || !isfinite(tolerance)) {
        fprintf(stderr, "viscera-resim: --tolerance '%s' is not a length in m >= 0\n", optarg);
        return 2;
      }
      break;
    case 'h':
      usage(stdout);
      return 0;
    default:
      usage(stderr);
      return 2;
    }
  }
  if (!scene_path || optind != argc - 1) {
    fprintf(stderr, "viscera-resim: %s\n", !scene_path ? "--scene FILE is required" : "expected one recording REC.db");
    usage(stderr);
    return 2;
  }
  const char *rec_path = argv[optind];

  verr_t err;
  static scene_t scene; /* large; static keeps it off the stack */
  if (scene_load(scene_path, &scene, &err)) {
    fprintf(stderr, "viscera-resim: %s\n", err.msg);
    return 2;
  }
  static resim_recording_t rec;
  if (resim_recording_load(&rec, rec_path, &err)) {
    fprintf(stderr, "viscera-resim: %s\n", err.msg);
    return 2;
  }
  if (rec.warnings[0]) fprintf(stderr, "viscera-resim: warning: %s\n", rec.warnings);
  if (rec.skipped)
    fprintf(stderr, "viscera-resim: warning: %" PRIu64 " sample(s) skipped; first: %s\n", rec.skipped, rec.first_skip);
  static runtime_t rt;
  if (runtime_init(&rt, &scene, &err)) {
    fprintf(stderr, "viscera-resim: %s\n", err.msg);
    resim_recording_free(&rec);
    return 2;
  }
  int rc = 2;
  FILE *csv = NULL;
  if (resim_check_scene(&rt, &rec, &err)) {
    fprintf(stderr, "viscera-resim: %s: refusing to re-simulate: %s\n", rec_path, err.msg);
    goto out;
  }
  if (csv_path) {
    csv = fopen(csv_path, "w");
    if (!csv) {
      fprintf(stderr, "viscera-resim: %s: cannot open for writing\n", csv_path);
      goto out;
    }
    fprintf(csv, "step,sim_time_s,organ,kind,max_err_m,rms_err_m,exact\n");
  }
  if (tolerance < 0) tolerance = 0.5 * (double)rec.quant_step + RESIM_FLOAT_SLACK;
  if (!quiet)
    fprintf(stderr,
            "resim: scene '%s', %zu organ(s), %zu tool(s); recording %s: %" PRIu64 " commands, %" PRIu64
            " feedback, %" PRIu64 " keyframes, %" PRIu64 " deltas, last frame at step %" PRIu64 " (%.3f s)\n",
            scene.name, rt.norgans, rt.ntools, rec_path, rec.n_commands, rec.n_feedback, rec.n_states, rec.n_deltas,
            rec.last_step, (double)rec.last_step * scene.dt);
  cli_ctx_t ctx = {.csv = csv, .dt = scene.dt, .quiet = quiet, .t0 = vtime_mono_ns()};
  ctx.last_print = ctx.t0;
  resim_hooks_t hooks = {.frame = on_frame, .progress = on_progress, .arg = &ctx};
  static resim_result_t res;
  if (resim_run(&rt, &rec, &hooks, &res, &err)) {
    fprintf(stderr, "viscera-resim: %s: %s\n", rec_path, err.msg);
    goto out;
  }
  double wall = (double)(vtime_mono_ns() - ctx.t0) * 1e-9;

  for (size_t t = 0; t < rt.ntools; t++) {
    const resim_schedule_stats_t *s = &res.sched[t];
    /* The recorded command stream itself (sorted by seq by now): a client
     * numbers its commands 1, 2, ..., so seqs missing between the first and
     * the last recorded are samples the recorder lost mid-session, and
     * first - 1 those sent before it (or the server) matched the writer. */
    const resim_tool_input_t *in = &rec.tools[t];
    uint64_t distinct = 0, first = in->ncmd ? in->cmd[0].seq : 0, last = in->ncmd ? in->cmd[in->ncmd - 1].seq : 0;
    for (size_t i = 0; i < in->ncmd; i++) distinct += i == 0 || in->cmd[i].seq != in->cmd[i - 1].seq;
    printf("SCHEDULE tool=%s feedback_steps=%" PRIu64 " gaps=%" PRIu64 " bridged_steps=%" PRIu64
           " ambiguous_steps=%" PRIu64 " missing_commands=%" PRIu64 " conflicts=%" PRIu64 " releases=%" PRIu64
           " cmd_first_seq=%" PRIu64 " cmd_last_seq=%" PRIu64 " cmd_seq_gaps=%" PRIu64 "\n",
           rt.tools[t].cfg->name, s->feedback_steps, s->gaps, s->bridged_steps, s->ambiguous_steps, s->missing_commands,
           s->conflicts, s->releases, first, last, in->ncmd ? last - first + 1 - distinct : 0);
  }
  int beyond = 0, compared = 0;
  for (size_t i = 0; i < rt.norgans; i++) {
    const resim_organ_result_t *r = &res.organs[i];
    double rms = r->nsq ? sqrt(r->sum_sq / (double)r->nsq) : 0;
    printf("ORGAN %s frames=%" PRIu64 " keyframes=%" PRIu64 " exact=%" PRIu64 " unmatched=%" PRIu64
           " max_err_m=%.3g rms_err_m=%.3g worst_step=%" PRIu64 "\n",
           rt.organs[i].cfg->name, r->frames, r->keyframes, r->exact, r->unmatched, r->max_err, rms, r->worst_step);
    /* MeshDelta frame_seq counts every published frame of the organ. */
    uint64_t dfirst = 0, dlast = 0, ddistinct = 0, dprev = 0;
    for (size_t j = 0; j < rec.ndeltas; j++) {
      const resim_delta_t *d = &rec.deltas[j];
      if (d->organ != i) continue;
      if (!ddistinct || d->frame_seq < dfirst) dfirst = d->frame_seq;
      if (!ddistinct || d->frame_seq > dlast) dlast = d->frame_seq;
      if (!ddistinct || d->frame_seq != dprev) ddistinct++;
      dprev = d->frame_seq;
    }
    printf("STREAM organ=%s delta_first_seq=%" PRIu64 " delta_last_seq=%" PRIu64 " delta_seq_gaps=%" PRIu64 "\n",
           rt.organs[i].cfg->name, dfirst, dlast, ddistinct ? dlast - dfirst + 1 - ddistinct : 0);
    if (r->frames) compared = 1;
    if (r->max_err > tolerance) {
      beyond = 1;
      fprintf(stderr,
              "viscera-resim: organ '%s' differs from the recording by %.3g m (at step %" PRIu64
              ", t = %.3f s), beyond the tolerance %.3g m: the re-simulation does not reproduce the session\n",
              rt.organs[i].cfg->name, r->max_err, r->worst_step, (double)r->worst_step * scene.dt, tolerance);
    }
  }
  if (res.first_unmatched[0])
    fprintf(stderr, "viscera-resim: warning: frames not compared; first: %s\n", res.first_unmatched);
  if (!compared) {
    fprintf(stderr, "viscera-resim: %s: no mesh frame recorded: nothing to compare\n", rec_path);
    goto out;
  }
  printf("RESIM %s steps=%" PRIu64 " rollbacks=%" PRIu64 " tolerance_m=%.3g wall_s=%.2f\n", beyond ? "FAIL" : "PASS",
         res.steps, res.rollbacks, tolerance, wall);
  rc = beyond ? 1 : 0;
out:
  if (csv && fclose(csv) != 0) {
    fprintf(stderr, "viscera-resim: %s: write failed\n", csv_path);
    rc = 2;
  }
  runtime_destroy(&rt);
  resim_recording_free(&rec);
  return rc;
}
