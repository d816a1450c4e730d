/* SPDX-License-Identifier: Apache-2.0 */
#include "recorder_run.h"

#include <signal.h>
#include <stdint.h>
#include <stdio.h>

#include "cli.h"
#include "dds/vdds_config.h"
#include "vsignal.h"
#include "vtime.h"

static volatile sig_atomic_t stop_requested = 0;

static void on_signal(int sig) {
  (void)sig;
  stop_requested = 1;
}

int recorder_run(const recorder_options_t *ro) {
  char version[64]; /* stored in the session metadata */
  snprintf(version, sizeof version, "viscera-recorder %s", cli_version());
  /* Install before the session exists so an early Ctrl-C still closes the
   * file cleanly; SA_RESETHAND makes a second signal kill at once. */
  vsignal_on_stop(on_signal, SA_RESETHAND);
  /* Past a file-size limit (ulimit -f) a write must fail with EFBIG, which
   * the store handles like a full disk, instead of SIGXFSZ killing the
   * recorder mid-batch. */
  signal(SIGXFSZ, SIG_IGN);

  verr_t err = {{0}};
  rec_session_t *s = NULL;
  if (rec_session_open(&s, &ro->session, version, &err) < 0) {
    fprintf(stderr, "recorder: %s\n", err.msg);
    return 1;
  }
  if (!ro->quiet)
    fprintf(stderr, "recorder: recording domain %d partition '%s' to %s\n", ro->session.domain, ro->session.partition,
            ro->session.out);

  const uint64_t t0 = vtime_mono_ns();
  const uint64_t t_end = ro->duration > 0 ? t0 + (uint64_t)(ro->duration * 1e9) : UINT64_MAX;
  uint64_t next_progress = t0 + 1000000000u, last_samples = 0, last_progress = t0;
  int status = 0, told = 0;
  while (!stop_requested) {
    uint64_t now = vtime_mono_ns();
    if (now >= t_end) break;
    if (!told) { /* no writer in the partition yet: say why that may be, once */
      rec_session_stats_t st;
      rec_session_get_stats(s, &st);
      if (vdds_nothing_seen_due(&told, (int)(st.topics + st.failed_topics), t0, now))
        vdds_explain_nothing_seen(stderr, "recorder", "no writer in this partition", ro->session.domain,
                                  ro->session.partition, VDDS_NOTHING_SEEN_S);
    }
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
    if (!ro->quiet && now >= next_progress) {
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
    if (!st.disk_full) fprintf(stderr, "recorder: closing %s: %s\n", ro->session.out, err.msg);
    status = 1;
  }
  if (st.disk_full) {
    fprintf(stderr,
            "recorder: disk full: recording stopped, %llu samples saved in %s (readable; no end time, the session "
            "went on)\n",
            (unsigned long long)st.samples, ro->session.out);
    status = 1;
  }
  if (st.failed_topics) fprintf(stderr, "recorder: %u topic(s) could not be recorded (see above)\n", st.failed_topics);
  fprintf(stderr, "recorder: wrote %llu samples of %u topics to %s\n", (unsigned long long)st.samples, st.topics,
          ro->session.out);
  printf("SUMMARY samples=%llu topics=%u bytes=%llu\n", (unsigned long long)st.samples, st.topics,
         (unsigned long long)st.bytes);
  return status;
}
