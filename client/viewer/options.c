/* SPDX-License-Identifier: Apache-2.0 */
#include "options.h"

#include <errno.h>
#include <getopt.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/vdds.h"
#include "view/camera.h"
#include "view/render.h"

void options_usage(FILE *f, const char *prog) {
  fprintf(f,
          "Usage: %s [OPTION]...\n"
          "Offscreen viewer: subscribes to a viscera scene over DDS and writes lit, shaded\n"
          "PNG frames of the organs and tools, with an index in DIR/frames.csv.\n"
          "\n"
          "  --domain N         DDS domain id 0..230 (default: $VISCERA_DOMAIN, else 0)\n" CLI_HELP_INSECURE
          "  --partition P      session partition (default " VDDS_DEFAULT_PARTITION ")\n"
          "  --out DIR          output directory, created if missing (default ./frames)\n"
          "  --interval-ms MS   write a frame every MS ms of wall time once a keyframe\n"
          "                     has arrived (default 100); 0 = only on demand\n"
          "  --width W          frame width in pixels, 16..%d (default 640)\n"
          "  --height H         frame height in pixels, 16..%d (default 480)\n"
          "  --tools on|off     draw tools, contact proxy and force bar (default on)\n"
          "  --duration S       exit after S seconds (default: until SIGINT/SIGTERM)\n"
          "  --max-frames N     exit after writing N frames\n"
          "  --dump-mesh PATH   on exit write each organ's current mesh as OBJ to PATH;\n"
          "                     with more than one organ, to PATH.<organ id>. First line:\n"
          "                     '# organ <id> topology <v> keyframe <k> frame <frame_seq>'\n"
          "                     (frame -1: no delta applied to the keyframe)\n"
          "  --window           show the scene in a window (SDL2) instead of writing\n"
          "                     frames; frames are still written when --out is given%s\n"
          "  --drive N          with --window: drive tool N with mouse and keyboard: mouse\n"
          "                     moves the tip in the view plane, wheel or W/S (held) in\n"
          "                     depth, left button or space = button 0 (grasp/cut), R resets,\n"
          "                     Esc quits; ToolCommand is published at 1 kHz\n"
          "  --script-input F   with --drive: play timed input events from F (lines\n"
          "                     'T motion DX DY', 'T wheel N', 'T key_down|key_up w|s|r|space',\n"
          "                     'T button_down|button_up'; T in s since the first frame),\n"
          "                     a demo and testing aid; without --duration the window\n"
          "                     closes 1 s after the last event\n"
          "  --quiet            no progress lines (the summary and errors still print)\n"
          "  --help             show this help and exit\n"
          "  --version          print the version and exit\n"
          "\n"
          "Signals: SIGUSR1 writes a frame now (or as soon as a keyframe is here);\n"
          "SIGINT/SIGTERM stop cleanly (exit 0).\n"
          "\n"
          "Frames are DIR/frame_00000.png, ... Each frame adds a row to DIR/frames.csv:\n"
          "  frame,file,wall_ms,sim_time_s,frame_seq,in_contact,force_n,tool_px,tool_py,proxy_px,proxy_py\n"
          "wall_ms: ms since the viewer started; sim_time_s: newest mesh sample's sim\n"
          "time (-1 if none); frame_seq: newest applied MeshDelta (-1 if none); contact,\n"
          "force (N) and positions follow the lowest-numbered active tool; *_px, *_py\n"
          "are pixel coordinates in the PNG (x right, y down) of the tool tip and of the\n"
          "contact proxy (-1 if unknown or not in contact).\n"
          "\n"
          "The camera is fixed once, from the bounds of the first keyframes (so frames are\n"
          "comparable): it looks at their centre from the front (-y side, turned %g degrees\n"
          "towards +x) and %g degrees above, far enough that all of them are in view.\n"
          "\n"
          "On exit prints 'viewer: N frames written to DIR' and 'SUMMARY frames=N\n"
          "rejected=M ignored=I gate_dropped=G keyframes_chunks=C keyframes_state=S\n"
          "keyframes_duplicate=D' (M: samples refused as malformed; I: samples of server\n"
          "topics not from the seat's server; G: samples its readers' gates dropped: ids\n"
          "beyond the tables, writers blocked; C, S: keyframes drawn from MeshKeyChunk\n"
          "chunk sets and from MeshState; D: second copies by the other path, skipped).\n"
          "The first keyframe is announced as 'viewer: first keyframe T ms after start,\n"
          "as chunks (MeshKeyChunk)|MeshState'.\n"
          "Exit status: 0 on success or SIGINT/SIGTERM, 1 when OSMesa, DDS or output setup\n"
          "fails, 2 on bad usage.\n"
          "DDS configuration comes from CYCLONEDDS_URI.\n",
          prog, RENDER_MAX_SIZE, RENDER_MAX_SIZE,
#ifdef VISCERA_HAVE_WINDOW
          "",
#else
          " (not in this build:\n                     SDL2 was not found)",
#endif
          CAMERA_AZIMUTH_DEG, CAMERA_ELEVATION_DEG);
}

static int parse_long(const char *s, long lo, long hi, long *out) {
  char *end = NULL;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (!*s || *end || errno || v < lo || v > hi) return -1;
  *out = v;
  return 0;
}

/* Refuses a value: the message, the hint, and the usage exit code 2. */
static int refuse(const char *fmt, const char *arg, int n) {
  fprintf(stderr, "viscera-viewer: ");
  fprintf(stderr, fmt, arg, n);
  fprintf(stderr, "\nTry 'viscera-viewer --help'.\n");
  return 2;
}

enum {
  O_OUT = 256,
  O_INTERVAL,
  O_WIDTH,
  O_HEIGHT,
  O_TOOLS,
  O_DURATION,
  O_MAX,
  O_DUMP,
  O_DRIVE,
  O_SCRIPT,
  O_WINDOW,
};

/* The viewer's own options (cli_option_fn); the common ones are cli.c's. */
static int viewer_option(void *ctx, int code, const char *arg) {
  viewer_opts_t *o = ctx;
  long v;
  char *end = NULL;
  switch (code) {
  case O_OUT:
    if (!*arg) return refuse("--out: empty directory name%.0s", arg, 0);
    o->out_dir = arg;
    o->out_set = 1;
    return 0;
  case O_INTERVAL:
    if (parse_long(arg, 0, 3600000, &v)) return refuse("--interval-ms '%s': expected 0..3600000", arg, 0);
    o->interval_ms = (int)v;
    return 0;
  case O_WIDTH:
  case O_HEIGHT:
    if (parse_long(arg, 16, RENDER_MAX_SIZE, &v))
      return refuse(code == O_WIDTH ? "--width '%s': expected 16..%d" : "--height '%s': expected 16..%d", arg,
                    RENDER_MAX_SIZE);
    *(code == O_WIDTH ? &o->width : &o->height) = (int)v;
    return 0;
  case O_TOOLS:
    if (strcmp(arg, "on") != 0 && strcmp(arg, "off") != 0) return refuse("--tools '%s': expected on or off", arg, 0);
    o->tools = strcmp(arg, "on") == 0;
    return 0;
  case O_DURATION:
    errno = 0;
    o->duration_s = strtod(arg, &end);
    /* The cap keeps the nanosecond count far inside uint64_t. */
    if (!*arg || *end || errno || !(o->duration_s > 0 && o->duration_s <= 1e8))
      return refuse("--duration '%s': expected seconds, > 0 and <= 1e8", arg, 0);
    return 0;
  case O_MAX:
    if (parse_long(arg, 1, 100000000, &v)) return refuse("--max-frames '%s': expected 1..100000000", arg, 0);
    o->max_frames = v;
    return 0;
  case O_DUMP:
    if (!*arg) return refuse("--dump-mesh: empty path%.0s", arg, 0);
    o->dump_mesh = arg;
    return 0;
  case O_WINDOW:
    o->window = 1;
    return 0;
  case O_DRIVE:
    if (parse_long(arg, 0, 7, &v)) return refuse("--drive '%s': expected a tool id 0..7", arg, 0);
    o->drive_tool = (int)v;
    return 0;
  case O_SCRIPT:
    if (!*arg) return refuse("--script-input: empty path%.0s", arg, 0);
    o->script_input = arg;
    return 0;
  }
  return 2;
}

static void usage_text(FILE *f) { options_usage(f, "viscera-viewer"); }

int options_parse(viewer_opts_t *o, int argc, char **argv) {
  *o = (viewer_opts_t){.domain = 0,
                       .partition = VDDS_DEFAULT_PARTITION,
                       .out_dir = "./frames",
                       .interval_ms = 100,
                       .width = 640,
                       .height = 480,
                       .tools = 1,
                       .drive_tool = -1};
  static const struct option longopts[] = {{"out", required_argument, NULL, O_OUT},
                                           {"interval-ms", required_argument, NULL, O_INTERVAL},
                                           {"width", required_argument, NULL, O_WIDTH},
                                           {"height", required_argument, NULL, O_HEIGHT},
                                           {"tools", required_argument, NULL, O_TOOLS},
                                           {"duration", required_argument, NULL, O_DURATION},
                                           {"max-frames", required_argument, NULL, O_MAX},
                                           {"dump-mesh", required_argument, NULL, O_DUMP},
                                           {"window", no_argument, NULL, O_WINDOW},
                                           {"drive", required_argument, NULL, O_DRIVE},
                                           {"script-input", required_argument, NULL, O_SCRIPT},
                                           {NULL, 0, NULL, 0}};
  const cli_spec_t spec = {.program = "viscera-viewer",
                           .common = CLI_DOMAIN | CLI_DOMAIN_ENV | CLI_PARTITION | CLI_QUIET,
                           .options = longopts,
                           .option = viewer_option,
                           .shortopts = "h",
                           .usage = usage_text,
                           .domain_error = "--domain '%s': expected an integer 0..230",
                           .partition_error = "--partition: empty partition name"};
  cli_common_t common = {.domain = 0};
  optind = 1;
  int rc = cli_parse(&spec, argc, argv, &common, o);
  if (rc != CLI_RUN) return rc;
  o->domain = common.domain;
  if (common.partition) o->partition = common.partition;
  o->quiet = common.quiet;
  const char *why = NULL;
  if (optind < argc)
    return refuse("unexpected argument '%s'", argv[optind], 0);
  else if (o->drive_tool >= 0 && !o->window)
    why = "--drive needs --window (input comes from the window)";
  else if (o->script_input && o->drive_tool < 0)
    why = "--script-input needs --drive N";
#ifndef VISCERA_HAVE_WINDOW
  else if (o->window)
    why = "--window: this viewer was built without SDL2 (install libsdl2-dev and rebuild with "
          "VISCERA_BUILD_WINDOW=ON)";
#endif
  if (why) return refuse("%s", why, 0);
  return CLI_RUN;
}
