/* SPDX-License-Identifier: Apache-2.0 */
#include "viewer_run.h"

#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "dds/vdds_config.h"
#include "view/camera.h"
#include "view/frame_log.h"
#include "mesh_dump.h"
#include "view/png_write.h"
#include "view/render.h"
#include "view/scene_draw.h"
#include "view/scene_view.h"
#include "vtime.h"
#ifdef VISCERA_HAVE_WINDOW
#include "window.h"
#include "dds/vdds_ident.h"
#endif

#define POLL_NS 10000000ull /* 10 ms */
/* After the first keyframe, wait at most this long for the keyframes of the
 * other organs before fixing the camera (they normally arrive within ms). */
#define KEYFRAME_GRACE_NS 500000000ull
#define SUPERSAMPLE 2
/* Rejections printed in full before only every REJECT_EVERY-th is. */
#define REJECT_PRINT_FIRST 20
#define REJECT_EVERY 1000

static volatile sig_atomic_t g_stop = 0;
static volatile sig_atomic_t g_snapshot = 0;

static void on_signal(int sig) {
  if (sig == SIGUSR1)
    g_snapshot = 1;
  else
    g_stop = 1;
}

static void install_signals(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  sigaction(SIGUSR1, &sa, NULL);
}

/* A flood of bad samples must not flood stderr: print the first few, then a
 * sample of the rest; the count in the summary is exact. */
static void log_reject(void *ctx, const char *msg) {
  unsigned long *n = ctx;
  ++*n;
  if (*n <= REJECT_PRINT_FIRST || *n % REJECT_EVERY == 0) fprintf(stderr, "viewer: rejected #%lu: %s\n", *n, msg);
  if (*n == REJECT_PRINT_FIRST)
    fprintf(stderr, "viewer: further rejections are counted; only every %dth is printed\n", REJECT_EVERY);
}

static int write_frame(render_t *r, const camera_t *cam, const scene_view_t *sv, frame_log_t *fl,
                       const viewer_opts_t *o, double wall_ms, verr_t *err) {
  char path[FRAME_LOG_DIR_LEN + 32];
  if (frame_log_next_path(fl, path, sizeof path, err)) return -1;
  const uint8_t *img = scene_draw(r, cam, sv, o->tools, err);
  if (!img || png_write_rgb(path, o->width, o->height, img, 1, err)) return -1;
  frame_row_t row = {.wall_ms = wall_ms};
  scene_draw_readouts(cam, sv, &row);
  return frame_log_add(fl, &row, err);
}

static void print_scene(const scene_view_t *sv, const camera_t *cam) {
  if (sv->have_scene) printf("viewer: scene '%s'\n", sv->scene_name);
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++) {
    const sv_organ_t *o = &sv->organs[i];
    if (o->mesh.have_key)
      printf("viewer: organ %d '%s': %zu vertices, %zu triangles (topology %u, keyframe %u)\n", i, o->name,
             o->mesh.nverts, o->mesh.ntris, o->mesh.topology_version, o->mesh.keyframe_seq);
    else if (o->listed)
      printf("viewer: organ %d '%s': no keyframe yet\n", i, o->name);
  }
  printf("viewer: camera fixed: looking at (%.4g, %.4g, %.4g) from (%.4g, %.4g, %.4g), scene radius %.4g m\n",
         cam->target[0], cam->target[1], cam->target[2], cam->eye[0], cam->eye[1], cam->eye[2], cam->radius);
  fflush(stdout);
}

int viewer_run(const viewer_opts_t *o) {
  install_signals();
  verr_t err = {{0}};
#ifdef VISCERA_HAVE_WINDOW
  if (o->window) return window_main(o, &g_stop);
#endif

  frame_log_t fl;
  if (frame_log_open(&fl, o->out_dir, &err)) {
    fprintf(stderr, "viscera-viewer: output: %s\n", err.msg);
    return 1;
  }
  render_t *r = NULL;
  if (render_open(&r, o->width, o->height, SUPERSAMPLE, &err)) {
    fprintf(stderr, "viscera-viewer: renderer: %s\n", err.msg);
    frame_log_close(&fl, NULL);
    return 1;
  }
  unsigned long printed_rejects = 0;
  static scene_view_t sv;
  if (scene_view_open(&sv, o->domain, o->partition, log_reject, &printed_rejects, &err)) {
    fprintf(stderr, "viscera-viewer: %s\n", err.msg);
    render_close(r);
    frame_log_close(&fl, NULL);
    return 1;
  }
  if (!o->quiet) {
    printf("viewer: domain %d, partition '%s', %dx%d frames to %s every %d ms%s\n", o->domain, o->partition, o->width,
           o->height, o->out_dir, o->interval_ms, o->interval_ms ? "" : " (0: on SIGUSR1 only)");
    fflush(stdout);
  }

  const uint64_t t0 = vtime_mono_ns();
  const uint64_t interval_ns = (uint64_t)o->interval_ms * 1000000ull;
  const uint64_t duration_ns = (uint64_t)(o->duration_s * 1e9);
  uint64_t first_key_ns = 0, next_due = 0;
  int have_cam = 0, status = 0, told_nothing = 0;
  camera_t cam;
  while (!g_stop) {
    uint64_t now = vtime_mono_ns();
    if (duration_ns && now - t0 >= duration_ns) break;
    if (scene_view_poll(&sv, &err) < 0) {
      fprintf(stderr, "viscera-viewer: %s\n", err.msg);
      status = 1;
      break;
    }
    if (vdds_nothing_seen_due(&told_nothing, sv.have_scene || vdds_matched_writers(sv.rd_scene), t0, now))
      vdds_explain_nothing_seen(stderr, "viewer", "no server publishes a scene here", o->domain, o->partition,
                                VDDS_NOTHING_SEEN_S);
    if (!have_cam && scene_view_any_keyframe(&sv)) {
      if (!first_key_ns) {
        first_key_ns = now;
        if (!o->quiet)
          printf("viewer: first keyframe %.1f ms after start, as %s\n", (double)(sv.first_key_mono_ns - t0) * 1e-6,
                 sv.keys_from_chunks ? "chunks (MeshKeyChunk)" : "MeshState");
      }
      double bmin[3], bmax[3];
      if ((scene_view_complete(&sv) || now - first_key_ns >= KEYFRAME_GRACE_NS) &&
          scene_view_key_bounds(&sv, bmin, bmax) == 0 && camera_frame(&cam, bmin, bmax, o->width, o->height) == 0) {
        have_cam = 1;
        next_due = now;
        if (!o->quiet) print_scene(&sv, &cam);
      }
    }
    /* A SIGUSR1 before the first keyframe stays pending until there is
     * something to show. */
    if (have_cam && ((interval_ns && now >= next_due) || g_snapshot)) {
      g_snapshot = 0;
      if (write_frame(r, &cam, &sv, &fl, o, (double)(now - t0) * 1e-6, &err)) {
        fprintf(stderr, "viscera-viewer: %s\n", err.msg);
        status = 1;
        break;
      }
      if (interval_ns) {
        /* Keep the schedule; after a stall skip the missed frames. */
        uint64_t after = vtime_mono_ns();
        next_due += interval_ns;
        if (next_due <= after) next_due = after + interval_ns;
      }
      if (o->max_frames && fl.frames >= o->max_frames) break;
    }
    uint64_t wake = vtime_mono_ns() + POLL_NS;
    if (have_cam && interval_ns && next_due < wake) wake = next_due;
    if (duration_ns && t0 + duration_ns < wake) wake = t0 + duration_ns;
    vtime_sleep_until(wake);
  }

  if (o->dump_mesh) {
    int n = mesh_dump_obj(&sv, o->dump_mesh, &err);
    if (n < 0) {
      fprintf(stderr, "viscera-viewer: --dump-mesh: %s\n", err.msg);
      status = 1;
    } else if (n == 0) {
      fprintf(stderr, "viscera-viewer: --dump-mesh: no keyframe received, nothing written\n");
    } else if (!o->quiet) {
      printf("viewer: %d mesh%s written to %s%s\n", n, n > 1 ? "es" : "", o->dump_mesh, n > 1 ? ".<organ id>" : "");
    }
  }
  unsigned long rejected = sv.rejected, ignored = sv.ignored;
  unsigned long keys_chunks = sv.keys_from_chunks, keys_state = sv.keys_from_state, keys_dup = sv.keys_duplicate;
  uint64_t gated = vdds_gate_dropped(&sv.gate_state) + vdds_gate_dropped(&sv.gate_delta) +
                   vdds_gate_dropped(&sv.gate_cmd) + vdds_gate_dropped(&sv.gate_contact) +
                   vdds_gate_dropped(&sv.gate_object) + vdds_gate_dropped(&sv.gate_chunk);
  scene_view_close(&sv);
  render_close(r);
  if (frame_log_close(&fl, &err)) {
    fprintf(stderr, "viscera-viewer: %s\n", err.msg);
    status = 1;
  }
  printf("viewer: %ld frames written to %s\n", fl.frames, o->out_dir);
  printf("SUMMARY frames=%ld rejected=%lu ignored=%lu gate_dropped=%" PRIu64
         " keyframes_chunks=%lu keyframes_state=%lu keyframes_duplicate=%lu\n",
         fl.frames, rejected, ignored, gated, keys_chunks, keys_state, keys_dup);
  return status;
}
