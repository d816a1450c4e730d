#include "options.h"

#include <errno.h>
#include <getopt.h>
#include <stdlib.h>
#include <string.h>

#include "dds/vdds.h"
#include "view/camera.h"
#include "view/render.h"

void options_usage(FILE *f, const char *prog) {
  fprintf(f,
          "Usage: %s [OPTION]...\n"
          "Offscreen viewer: subscribes to a viscera scene over DDS and writes lit, shaded\n"
          "PNG frames of the organs and tools, with an index in DIR/frames.csv.\n"
          "\n"
          "  --domain N         DDS domain id 0..230 (default: $VISCERA_DOMAIN, else 0)\n"
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
          "rejected=M' (M: samples refused as malformed). Exit status: 0 on success or\n"
          "SIGINT/SIGTERM, 1 when OSMesa, DDS or output setup fails, 2 on bad usage.\n"
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

int options_parse(viewer_opts_t *o, int argc, char **argv, verr_t *err) {
  *o = (viewer_opts_t){.domain = 0,
                       .partition = VDDS_DEFAULT_PARTITION,
                       .out_dir = "./frames",
                       .interval_ms = 100,
                       .width = 640,
                       .height = 480,
                       .tools = 1,
                       .drive_tool = -1};
  if ((o->domain = vdds_env_domain(err)) < 0) return -1;
  enum {
    O_DOMAIN = 256,
    O_PARTITION,
    O_OUT,
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
    O_QUIET,
    O_HELP,
    O_VERSION
  };
  static const struct option longopts[] = {{"domain", required_argument, NULL, O_DOMAIN},
                                           {"partition", required_argument, NULL, O_PARTITION},
                                           {"out", required_argument, NULL, O_OUT},
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
                                           {"quiet", no_argument, NULL, O_QUIET},
                                           {"help", no_argument, NULL, O_HELP},
                                           {"version", no_argument, NULL, O_VERSION},
                                           {NULL, 0, NULL, 0}};
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, "", longopts, NULL)) != -1) {
    long v;
    char *end = NULL;
    switch (c) {
    case O_DOMAIN:
      o->domain = vdds_parse_domain(optarg);
      if (o->domain < 0) return verr_set(err, "--domain '%s': expected an integer 0..230", optarg);
      break;
    case O_PARTITION:
      if (!*optarg) return verr_set(err, "--partition: empty partition name");
      o->partition = optarg;
      break;
    case O_OUT:
      if (!*optarg) return verr_set(err, "--out: empty directory name");
      o->out_dir = optarg;
      o->out_set = 1;
      break;
    case O_INTERVAL:
      if (parse_long(optarg, 0, 3600000, &v)) return verr_set(err, "--interval-ms '%s': expected 0..3600000", optarg);
      o->interval_ms = (int)v;
      break;
    case O_WIDTH:
    case O_HEIGHT:
      if (parse_long(optarg, 16, RENDER_MAX_SIZE, &v))
        return verr_set(err, "--%s '%s': expected 16..%d", c == O_WIDTH ? "width" : "height", optarg, RENDER_MAX_SIZE);
      *(c == O_WIDTH ? &o->width : &o->height) = (int)v;
      break;
    case O_TOOLS:
      if (strcmp(optarg, "on") != 0 && strcmp(optarg, "off") != 0)
        return verr_set(err, "--tools '%s': expected on or off", optarg);
      o->tools = strcmp(optarg, "on") == 0;
      break;
    case O_DURATION:
      errno = 0;
      o->duration_s = strtod(optarg, &end);
      /* The cap keeps the nanosecond count far inside uint64_t. */
      if (!*optarg || *end || errno || !(o->duration_s > 0 && o->duration_s <= 1e8))
        return verr_set(err, "--duration '%s': expected seconds, > 0 and <= 1e8", optarg);
      break;
    case O_MAX:
      if (parse_long(optarg, 1, 100000000, &v))
        return verr_set(err, "--max-frames '%s': expected 1..100000000", optarg);
      o->max_frames = v;
      break;
    case O_DUMP:
      if (!*optarg) return verr_set(err, "--dump-mesh: empty path");
      o->dump_mesh = optarg;
      break;
    case O_WINDOW:
      o->window = 1;
      break;
    case O_DRIVE:
      if (parse_long(optarg, 0, 7, &v)) return verr_set(err, "--drive '%s': expected a tool id 0..7", optarg);
      o->drive_tool = (int)v;
      break;
    case O_SCRIPT:
      if (!*optarg) return verr_set(err, "--script-input: empty path");
      o->script_input = optarg;
      break;
    case O_QUIET:
      o->quiet = 1;
      break;
    case O_HELP:
      return 1;
    case O_VERSION:
      return 2;
    default:
      if ((optopt >= O_DOMAIN && optopt <= O_DUMP) || optopt == O_DRIVE || optopt == O_SCRIPT)
        return verr_set(err, "%s: missing value", argv[optind - 1]);
      return verr_set(err, "unknown option '%s'", argv[optind - 1]);
    }
  }
  if (optind < argc) return verr_set(err, "unexpected argument '%s'", argv[optind]);
  if (o->drive_tool >= 0 && !o->window) return verr_set(err, "--drive needs --window (input comes from the window)");
  if (o->script_input && o->drive_tool < 0) return verr_set(err, "--script-input needs --drive N");
#ifndef VISCERA_HAVE_WINDOW
  if (o->window)
    return verr_set(err, "--window: this viewer was built without SDL2 (install libsdl2-dev and rebuild with "
                         "VISCERA_BUILD_WINDOW=ON)");
#endif
  return 0;
}
