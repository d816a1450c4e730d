/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-resim after its options (resim.c): load the scene and the
 * recording, re-simulate, compare and print the SCHEDULE, ORGAN, STREAM and
 * RESIM lines. */
#include "resim/resim_app.h"

#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "build_id.h"
#include "cli.h"

#include "data_path.h"
#include "resim/resim_recording.h"
#include "resim/resim_run.h"
#include "resim/resim_scene.h"
#include "runtime/scene_runtime.h"
#include "scene.h"
#include "vtime.h"

/* Float rounding of a recorded position (keyframe float plus quantized
 * delta, |x| < 1 m): a few 1e-9 m. The default tolerance adds this to the
 * quantization bound quant_step / 2. */
#define RESIM_FLOAT_SLACK 5e-8

typedef struct progress_ctx {
  FILE *csv;
  double dt;
  int quiet;
  uint64_t t0, last_print;
} progress_ctx_t;

static void on_frame(void *arg, uint64_t step, uint32_t organ, int keyframe, double max_err, double rms, int exact) {
  progress_ctx_t *c = arg;
  if (c->csv)
    fprintf(c->csv, "%" PRIu64 ",%.6f,%u,%s,%.9g,%.9g,%d\n", step, (double)step * c->dt, organ,
            keyframe ? "keyframe" : "delta", max_err, rms, exact);
}

static void on_progress(void *arg, uint64_t step, uint64_t total) {
  progress_ctx_t *c = arg;
  uint64_t now = vtime_mono_ns();
  /* A line every 2 s of wall time, so long recordings show they move. */
  if (c->quiet || now - c->last_print < 2000000000ull || step == 0) return;
  c->last_print = now;
  double el = (double)(now - c->t0) * 1e-9;
  fprintf(stderr, "resim: step %" PRIu64 " / %" PRIu64 " (%.0f %%), %.1f s elapsed, %.1f s left\n", step, total,
          100.0 * (double)step / (double)total, el, el * (double)(total - step) / (double)step);
}

/* SCHEDULE lines: how each tool's command stream was rebuilt. */
static void print_schedules(const runtime_t *rt, const resim_recording_t *rec, const resim_result_t *res) {
  for (size_t t = 0; t < rt->ntools; t++) {
    const resim_schedule_stats_t *s = &res->sched[t];
    /* The recorded command stream itself (sorted by seq by now): a client
     * numbers its commands 1, 2, ..., so seqs missing between the first and
     * the last recorded are samples the recorder lost mid-session, and
     * first - 1 those sent before it (or the server) matched the writer. */
    const resim_tool_input_t *in = &rec->tools[t];
    uint64_t distinct = 0, first = in->ncmd ? in->cmd[0].seq : 0, last = in->ncmd ? in->cmd[in->ncmd - 1].seq : 0;
    for (size_t i = 0; i < in->ncmd; i++) distinct += i == 0 || in->cmd[i].seq != in->cmd[i - 1].seq;
    printf("SCHEDULE tool=%s feedback_steps=%" PRIu64 " gaps=%" PRIu64 " bridged_steps=%" PRIu64
           " ambiguous_steps=%" PRIu64 " missing_commands=%" PRIu64 " conflicts=%" PRIu64 " releases=%" PRIu64
           " cmd_first_seq=%" PRIu64 " cmd_last_seq=%" PRIu64 " cmd_seq_gaps=%" PRIu64 "\n",
           rt->tools[t].cfg->name, s->feedback_steps, s->gaps, s->bridged_steps, s->ambiguous_steps,
           s->missing_commands, s->conflicts, s->releases, first, last, in->ncmd ? last - first + 1 - distinct : 0);
  }
}

/* ORGAN and STREAM lines; returns whether an organ is beyond the
 * tolerance, *compared whether any frame was compared. */
static int print_organs(const runtime_t *rt, const resim_recording_t *rec, const resim_result_t *res,
                        const scene_t *scene, double tolerance, int *compared) {
  int beyond = 0;
  for (size_t i = 0; i < rt->norgans; i++) {
    const resim_organ_result_t *r = &res->organs[i];
    double rms = r->nsq ? sqrt(r->sum_sq / (double)r->nsq) : 0;
    printf("ORGAN %s frames=%" PRIu64 " keyframes=%" PRIu64 " exact=%" PRIu64 " unmatched=%" PRIu64
           " unreached=%" PRIu64 " max_err_m=%.3g rms_err_m=%.3g worst_step=%" PRIu64 "\n",
           rt->organs[i].cfg->name, r->frames, r->keyframes, r->exact, r->unmatched, r->unreached, r->max_err, rms,
           r->worst_step);
    /* MeshDelta frame_seq counts every published frame of the organ. */
    uint64_t dfirst = 0, dlast = 0, ddistinct = 0, dprev = 0;
    for (size_t j = 0; j < rec->ndeltas; j++) {
      const resim_delta_t *d = &rec->deltas[j];
      if (d->organ != i) continue;
      if (!ddistinct || d->frame_seq < dfirst) dfirst = d->frame_seq;
      if (!ddistinct || d->frame_seq > dlast) dlast = d->frame_seq;
      if (!ddistinct || d->frame_seq != dprev) ddistinct++;
      dprev = d->frame_seq;
    }
    printf("STREAM organ=%s delta_first_seq=%" PRIu64 " delta_last_seq=%" PRIu64 " delta_seq_gaps=%" PRIu64 "\n",
           rt->organs[i].cfg->name, dfirst, dlast, ddistinct ? dlast - dfirst + 1 - ddistinct : 0);
    if (r->frames) *compared = 1;
    if (res->applied && (r->unmatched || r->unreached)) {
      beyond = 1;
      fprintf(stderr,
              "viscera-resim: organ '%s': %" PRIu64
              " recorded frame(s) do not fit the re-simulated surface and %" PRIu64
              " were never reached (another topology or end): the re-simulation does not reproduce the session\n",
              rt->organs[i].cfg->name, r->unmatched, r->unreached);
    }
    if (r->max_err > tolerance) {
      beyond = 1;
      fprintf(stderr,
              "viscera-resim: organ '%s' differs from the recording by %.3g m (at step %" PRIu64
              ", t = %.3f s), beyond the tolerance %.3g m: the re-simulation does not reproduce the session\n",
              rt->organs[i].cfg->name, r->max_err, r->worst_step, (double)r->worst_step * scene->dt, tolerance);
    }
  }
  return beyond;
}

/* INPUTS, OBJECTS and EVENTS lines; returns whether they fail the run
 * (applied inputs only: an older recording knows no buttons or controls,
 * so only its meshes are judged). */
static int print_others(const resim_recording_t *rec, const resim_result_t *res, double tolerance) {
  int bad = 0;
  if (res->applied)
    printf("INPUTS mode=applied commands=%" PRIu64 " releases=%" PRIu64 " controls=%" PRIu64 " rebuilds=%" PRIu64
           " steps=%" PRIu64 " lost=%" PRIu64 "\n",
           res->commands, res->releases, res->controls, res->rebuilds, res->steps, rec->applied_lost);
  else
    printf("INPUTS mode=schedule (no AppliedInput recorded: tool positions only, from ToolCommand and "
           "ContactFeedback)\n");
  const resim_object_result_t *o = &res->objects;
  printf("OBJECTS compared=%" PRIu64 " exact=%" PRIu64 " mismatched=%" PRIu64 " unreached=%" PRIu64
         " max_err_m=%.3g worst_step=%" PRIu64 "\n",
         o->compared, o->exact, o->mismatched, o->unreached, o->max_err, o->worst_step);
  const resim_event_result_t *e = &res->events;
  printf("EVENTS recorded=%zu resim=%zu equal=%zu\n", e->recorded, e->resim, e->equal);
  const resim_metrics_result_t *m = &res->metrics;
  printf("TOOLMETRICS compared=%" PRIu64 " differ=%" PRIu64 " unreached=%" PRIu64 "\n", m->compared, m->differ,
         m->unreached);
  if (res->diverged) {
    bad = 1;
    fprintf(stderr, "viscera-resim: the re-simulation diverged from the recording: %s\n", res->divergence);
  }
  if (!res->applied) return bad;
  if (rec->applied_lost) {
    bad = 1;
    /* In a damaged file they are most likely in the part that could not be
     * read, not lost by the recorder. */
    bool damaged = rec->warnings[0] || rec->skipped;
    fprintf(stderr,
            "viscera-resim: %" PRIu64 " AppliedInput sample(s) are missing from the recording (%s): the inputs of "
            "those steps are unknown\n",
            rec->applied_lost,
            damaged ? "in the damaged part of the file named above, or lost by the recorder"
                    : "the recorder lost them");
  }
  if (o->mismatched || o->unreached || o->max_err > tolerance) {
    bad = 1;
    fprintf(stderr,
            "viscera-resim: objects differ from the recording: %" PRIu64 " with another holder or state (first at "
            "step %" PRIu64 "), %" PRIu64 " not reached, position error %.3g m at step %" PRIu64 "\n",
            o->mismatched, o->first_mismatch_step, o->unreached, o->max_err, o->worst_step);
  }
  if (e->first_difference[0]) {
    bad = 1;
    fprintf(stderr, "viscera-resim: interaction events differ from the recording: %s\n", e->first_difference);
  }
  if (m->differ || m->unreached) {
    bad = 1;
    fprintf(stderr,
            "viscera-resim: ToolMetrics differ from the recording: %" PRIu64 " differ, %" PRIu64 " not reached%s%s\n",
            m->differ, m->unreached, m->first_difference[0] ? "; first: " : "", m->first_difference);
  }
  return bad;
}

/* Every compared frame and object reproduced bit for bit, every event equal. */
static int bit_exact(const runtime_t *rt, const resim_result_t *res) {
  for (size_t i = 0; i < rt->norgans; i++) {
    const resim_organ_result_t *r = &res->organs[i];
    if (r->exact != r->frames || r->unmatched || r->unreached) return 0;
  }
  return res->objects.exact == res->objects.compared && !res->objects.unreached && !res->events.first_difference[0] &&
         !res->metrics.differ && !res->metrics.unreached && !res->diverged;
}

/* BUILD line: the build that recorded and this one. Bit-exact reproduction
 * is a property of one build; another one is judged the same way, against
 * the recording, and told. */
static void print_build(const resim_recording_t *rec) {
  const resim_source_t *s = &rec->source;
  if (!s->have) {
    printf("BUILD recorded=unknown this=\"%s %s %s\"\n", cli_version(), build_compiler(), build_flags());
    return;
  }
  int same = !strcmp(s->version, cli_version()) && !strcmp(s->compiler, build_compiler()) &&
             !strcmp(s->build_flags, build_flags());
  printf("BUILD same=%d recorded=\"%s %s %s\" this=\"%s %s %s\"\n", same, s->version, s->compiler, s->build_flags,
         cli_version(), build_compiler(), build_flags());
  if (!same)
    fprintf(stderr,
            "viscera-resim: note: the session ran on another build (%s, %s, %s): bit-exact reproduction is "
            "not expected, the errors below are against the recording\n",
            s->version, s->compiler, s->build_flags);
}

int resim_app_run(const resim_options_t *o) {
  verr_t err;
  static scene_t scene; /* large; static keeps it off the stack */
  /* An installed scene by name from any directory (data_path.h). */
  char scene_buf[DATA_PATH_MAX];
  const char *scene_path = o->scene_path;
  if (scene_path) {
    data_path_resolve(scene_path, "assets/scenes", scene_buf, sizeof scene_buf);
    scene_path = scene_buf;
  }
  static resim_recording_t rec;
  if (resim_recording_load(&rec, o->rec_path, o->partition, o->run, &err)) {
    fprintf(stderr, "viscera-resim: %s\n", err.msg);
    return 2;
  }
  if (resim_scene_load(&scene, scene_path, o->mesh_dir, &rec, stdout, &err)) {
    fprintf(stderr, "viscera-resim: %s: %s\n", o->rec_path, err.msg);
    resim_recording_free(&rec);
    return 2;
  }
  print_build(&rec);
  if (rec.partition[0]) printf("SESSION partition=%s\n", rec.partition);
  if (rec.run) {
    printf("RUN run=%zu runs=%zu\n", rec.run, rec.nruns);
    fprintf(stderr,
            "viscera-resim: note: the server ran %zu times in this session (restarted while the recorder ran): "
            "re-simulating run %zu%s, the other runs' samples left out (--run N picks another)\n",
            rec.nruns, rec.run, rec.run == rec.nruns ? ", the last" : "");
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
  if (resim_resume(&rt, &rec, &err)) {
    fprintf(stderr, "viscera-resim: %s: %s\n", o->rec_path, err.msg);
    goto out;
  }
  if (resim_check_scene(&rt, &rec, &err)) {
    fprintf(stderr, "viscera-resim: %s: refusing to re-simulate: %s\n", o->rec_path, err.msg);
    goto out;
  }
  if (o->csv_path) {
    csv = fopen(o->csv_path, "w");
    if (!csv) {
      fprintf(stderr, "viscera-resim: %s: cannot open for writing\n", o->csv_path);
      goto out;
    }
    fprintf(csv, "step,sim_time_s,organ,kind,max_err_m,rms_err_m,exact\n");
  }
  double tolerance = o->tolerance;
  if (tolerance < 0) tolerance = 0.5 * (double)rec.quant_step + RESIM_FLOAT_SLACK;
  if (!o->quiet)
    fprintf(stderr,
            "resim: scene '%s', %zu organ(s), %zu tool(s); recording %s: %" PRIu64 " commands, %" PRIu64
            " feedback, %" PRIu64 " keyframes, %" PRIu64 " deltas, last frame at step %" PRIu64 " (%.3f s)\n",
            scene.name, rt.norgans, rt.ntools, o->rec_path, rec.n_commands, rec.n_feedback, rec.n_states, rec.n_deltas,
            rec.last_step, (double)rec.last_step * scene.dt);
  progress_ctx_t ctx = {.csv = csv, .dt = scene.dt, .quiet = o->quiet, .t0 = vtime_mono_ns()};
  ctx.last_print = ctx.t0;
  resim_hooks_t hooks = {.frame = on_frame, .progress = on_progress, .arg = &ctx};
  static resim_result_t res;
  if (resim_run(&rt, &rec, &hooks, &res, &err)) {
    fprintf(stderr, "viscera-resim: %s: %s\n", o->rec_path, err.msg);
    goto out;
  }
  double wall = (double)(vtime_mono_ns() - ctx.t0) * 1e-9;
  if (rec.source.resumed)
    printf("RESUMED step=%" PRIu64 " t=%.3f checkpoint_sha256=%s state_bytes=%zu\n", res.resumed_step,
           (double)res.resumed_step * scene.dt, rec.source.resume_sha256[0] ? rec.source.resume_sha256 : "unknown",
           rec.source.resume_len);

  print_schedules(&rt, &rec, &res);
  int compared = 0, beyond = print_organs(&rt, &rec, &res, &scene, tolerance, &compared);
  beyond |= print_others(&rec, &res, tolerance);
  if (res.first_unmatched[0])
    fprintf(stderr, "viscera-resim: warning: frames not compared; first: %s\n", res.first_unmatched);
  if (!compared) {
    fprintf(stderr, "viscera-resim: %s: no mesh frame recorded: nothing to compare\n", o->rec_path);
    goto out;
  }
  printf("RESIM %s steps=%" PRIu64 " rollbacks=%" PRIu64 " tolerance_m=%.3g bit_exact=%d wall_s=%.2f\n",
         beyond ? "FAIL" : "PASS", res.steps, res.rollbacks, tolerance, bit_exact(&rt, &res), wall);
  rc = beyond ? 1 : 0;
out:
  if (csv && fclose(csv) != 0) {
    fprintf(stderr, "viscera-resim: %s: write failed\n", o->csv_path);
    rc = 2;
  }
  runtime_destroy(&rt);
  resim_recording_free(&rec);
  return rc;
}
