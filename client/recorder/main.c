/* viscera-recorder: records every topic of a session into one SQLite file.
 *
 * Generic by design: it compiles in no product type. Topics and their types
 * are discovered at run time (see session.h), so topics added to the
 * product later are recorded without rebuilding the recorder. */
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "session.h"
#include "vtime.h"
#include "vsignal.h"
#include "dds/vdds.h"

#ifndef VISCERA_VERSION
#define VISCERA_VERSION "unknown"
#endif
#define RECORDER_VERSION "viscera-recorder " VISCERA_VERSION

static volatile sig_atomic_t stop_requested = 0;

static void on_signal(int sig) {
  (void)sig;
  stop_requested = 1;
}

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-recorder --out FILE.db [options]\n"
             "Records every topic published in a DDS partition into one SQLite file\n"
             "(raw CDR plus type descriptors; read it with viscera-recinfo).\n"
             "\n"
             "  -o, --out FILE.db     recording to create (required)\n"
             "  -f, --force           overwrite FILE.db if it exists\n"
             "  -d, --domain N        DDS domain id 0..230 (default: $VISCERA_DOMAIN, else 0)\n"
             "  -p, --partition P     partition to record; fnmatch-style patterns such as\n"
             "                        'lab1/*' record several sessions (default: viscera/local)\n"
             "  -t, --duration S      stop after S seconds (default: until SIGINT/SIGTERM)\n"
             "  -s, --scene NAME      scene name stored in the session metadata\n"
             "      --depth N         reader history per instance, samples (default 1000):\n"
             "                        how long a stall of the recorder is absorbed\n"
             "  -q, --quiet           no progress line\n"
             "  -h, --help            this text\n"
             "\n"
             "Progress goes to stderr once per second. SIGINT/SIGTERM finish the current\n"
             "batch, write the end time and close the file; a second signal kills at once\n"
             "(the file stays readable, the last batch of at most 200 ms is lost).\n"
             "A full disk (or file-size limit) stops the recording cleanly: the file keeps\n"
             "every committed batch and stays readable, the recorder exits with status 1.\n"
             "Exit status: 0 done, 1 runtime error (disk full included), 2 usage error.\n"
             "DDS configuration comes from CYCLONEDDS_URI.\n");
}

int main(int argc, char **argv) {
  vdds_set_role("recorder"); /* announced in the participant USER_DATA */
  rec_session_opts_t o = {0};
  o.partition = "viscera/local";
  o.log = stderr;
  double duration = 0;
  bool quiet = false;
  {
    verr_t derr;
    if ((o.domain = vdds_env_domain(&derr)) < 0) {
      fprintf(stderr, "recorder: %s\n", derr.msg);
      return 2;
    }
  }
  enum { OPT_DEPTH = 1000 };
  static const struct option longopts[] = {
      {"out", required_argument, 0, 'o'},
      {"force", no_argument, 0, 'f'},
      {"domain", required_argument, 0, 'd'},
      {"partition", required_argument, 0, 'p'},
      {"duration", required_argument, 0, 't'},
      {"scene", required_argument, 0, 's'},
      {"depth", required_argument, 0, OPT_DEPTH},
      {"quiet", no_argument, 0, 'q'},
      {"help", no_argument, 0, 'h'},
      {0, 0, 0, 0},
  };
  int c;
  while ((c = getopt_long(argc, argv, "o:fd:p:t:s:qh", longopts, NULL)) != -1) {
    char *end = NULL;
    switch (c) {
    case 'o':
      o.out = optarg;
      break;
    case 'f':
      o.force = true;
      break;
    case 'd':
      if ((o.domain = vdds_parse_domain(optarg)) < 0) {
        fprintf(stderr, "recorder: --domain '%s': expected an integer 0..230\n", optarg);
        return 2;
      }
      break;
    case 'p':
      if (!*optarg) {
        fprintf(stderr, "recorder: --partition: empty pattern\n");
        return 2;
      }
      o.partition = optarg;
      break;
    case 't':
      duration = strtod(optarg, &end);
      if (!*optarg || *end || !isfinite(duration) || duration <= 0 || duration > 1e7) {
        fprintf(stderr, "recorder: --duration '%s': expected seconds > 0\n", optarg);
        return 2;
      }
      break;
    case 's':
      o.scene = optarg;
      break;
    case OPT_DEPTH: {
      long d = strtol(optarg, &end, 10);
      if (!*optarg || *end || d < 1 || d > 1000000) {
        fprintf(stderr, "recorder: --depth '%s': expected 1..1000000\n", optarg);
        return 2;
      }
      o.depth = (int32_t)d;
      break;
    }
    case 'q':
      quiet = true;
      break;
    case 'h':
      usage(stdout);
      return 0;
    default:
      usage(stderr);
      return 2;
    }
  }
  if (optind < argc) {
    fprintf(stderr, "recorder: unexpected argument '%s'\n", argv[optind]);
    usage(stderr);
    return 2;
  }
  if (!o.out) {
    fprintf(stderr, "recorder: --out FILE.db is required\n");
    usage(stderr);
    return 2;
  }

  /* Install before the session exists so an early Ctrl-C still closes the
   * file cleanly; SA_RESETHAND makes a second signal kill at once. */
  vsignal_on_stop(on_signal, SA_RESETHAND);
  /* Past a file-size limit (ulimit -f) a write must fail with EFBIG, which
   * the store handles like a full disk, instead of SIGXFSZ killing the
   * recorder mid-batch. */
  signal(SIGXFSZ, SIG_IGN);

  verr_t err = {{0}};
  rec_session_t *s = NULL;
  if (rec_session_open(&s, &o, RECORDER_VERSION, &err) < 0) {
    fprintf(stderr, "recorder: %s\n", err.msg);
    return 1;
  }
  if (!quiet) fprintf(stderr, "recorder: recording domain %d partition '%s' to %s\n", o.domain, o.partition, o.out);

  const uint64_t t0 = vtime_mono_ns();
  const uint64_t t_end = duration > 0 ? t0 + (uint64_t)(duration * 1e9) : UINT64_MAX;
  uint64_t next_progress = t0 + 1000000000u, last_samples = 0, last_progress = t0;
  int status = 0;
  while (!stop_requested) {
    uint64_t now = vtime_mono_ns();
    if (now >= t_end) break;
    /* Short waits: the loop also commits batches on time and notices
     * signals, which cannot wake a DDS waitset safely. */
    dds_duration_t wait = DDS_MSECS(50);
    if (t_end - now < (uint64_t)wait) wait = (dds_duration_t)(t_end - now);
    if (rec_session_step(s, wait, &err) < 0) {
      fprintf(stderr, "recorder: stopping: %s\n", err.msg);
      status = 1;
      break;
    }
    now = vtime_mono_ns();
    if (!quiet && now >= next_progress) {
      rec_session_stats_t st;
      rec_session_get_stats(s, &st);
      double dt = (double)(now - last_progress) * 1e-9;
      fprintf(stderr, "recorder: %llu samples (%.0f/s), %.1f MB, %u topics\n", (unsigned long long)st.samples,
              dt > 0 ? (double)(st.samples - last_samples) / dt : 0.0, (double)st.bytes / 1e6, st.topics);
      last_samples = st.samples;
      last_progress = now;
      next_progress = now + 1000000000u;
    }
  }
  rec_session_stats_t st = {0};
  if (rec_session_close(s, &st, &err) < 0) {
    if (!st.disk_full) fprintf(stderr, "recorder: closing %s: %s\n", o.out, err.msg);
    status = 1;
  }
  if (st.disk_full) {
    fprintf(stderr,
            "recorder: disk full: recording stopped, %llu samples saved in %s (readable; no end time, the session "
            "went on)\n",
            (unsigned long long)st.samples, o.out);
    status = 1;
  }
  if (st.failed_topics) fprintf(stderr, "recorder: %u topic(s) could not be recorded (see above)\n", st.failed_topics);
  fprintf(stderr, "recorder: wrote %llu samples of %u topics to %s\n", (unsigned long long)st.samples, st.topics,
          o.out);
  printf("SUMMARY samples=%llu topics=%u bytes=%llu\n", (unsigned long long)st.samples, st.topics,
         (unsigned long long)st.bytes);
  return status;
}
