/* SPDX-License-Identifier: Apache-2.0 */
#include "haptic_summary.h"

#include <inttypes.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>

#include "vstats.h"

void haptic_summary_print(const haptic_options_t *o, haptic_stats_t *st, haptic_dds_t *h, const guide_report_t *guide) {
  vstats_summary_t per = vstats_summarise(st->period_us, st->nperiod);
  pthread_mutex_lock(&h->slot.lock);
  vstats_summary_t lat = vstats_summarise(h->slot.latency_us, h->slot.nlatency);
  uint64_t feedback = h->slot.received, live_lost = h->slot.lost_events, live_back = h->slot.regained_events;
  uint64_t foreign = h->slot.foreign_echoes;
  uint64_t ignored = h->slot.ignored, beyond = h->slot.out_of_limits, stale = h->slot.stale;
  pthread_mutex_unlock(&h->slot.lock);
  uint64_t gate_dropped = vdds_gate_dropped(&h->slot.gate);
  /* Jitter: the p99 of |period - nominal| (early and late ticks alike). */
  for (size_t i = 0; i < st->nperiod; i++) st->period_us[i] = fabs(st->period_us[i] - 1e6 / o->rate);
  vstats_summary_t jit = vstats_summarise(st->period_us, st->nperiod);
  double jitter_p99 = jit.p99;
  fprintf(stderr,
          "haptic: %" PRIu64 " ticks in %.2f s (%.1f Hz); period median %.1f us, p99 %.1f us, max %.1f us; "
          "%" PRIu64 " ticks over 1 ms late; jitter p99 %.1f us\n",
          st->ticks, st->elapsed_s, (double)st->ticks / st->elapsed_s, per.median, per.p99, per.max, st->late_ticks,
          jitter_p99);
  if (o->start_on_answer) {
    if (st->script_start_s >= 0)
      fprintf(stderr, "haptic: path started at %.3f s of the loop (--start-on-answer)\n", st->script_start_s);
    else
      fprintf(stderr, "haptic: path never started (no answer, --start-on-answer)\n");
  }
  fprintf(
      stderr,
      "haptic: force peak %.3f N, mean in contact %.3f N, %" PRIu64 " ticks in contact, %" PRIu64 " feedback samples\n",
      st->peak_force, st->contact_ticks ? st->force_sum / (double)st->contact_ticks : 0.0, st->contact_ticks, feedback);
  if (live_lost || live_back)
    fprintf(stderr, "haptic: server liveliness lost %" PRIu64 " time(s), regained %" PRIu64 " time(s)\n", live_lost,
            live_back);
  fprintf(stderr, "haptic: command->feedback latency median %.1f us, p99 %.1f us (%zu samples)\n", lat.median, lat.p99,
          lat.n);
  if (foreign)
    fprintf(stderr, "haptic: %" PRIu64 " feedback samples answered another station's commands (not in the latency)\n",
            foreign);
  if (ignored || beyond || stale || gate_dropped)
    fprintf(stderr,
            "haptic: feedback: %" PRIu64 " samples ignored (not the seat's server) and %" PRIu64
            " dropped at the reader (other tools, blocked writers), %" PRIu64 " beyond the scene's limits, %" PRIu64
            " older than one already used\n",
            ignored, gate_dropped, beyond, stale);
  guide_report_summary(guide, 1.0 / o->rate, stderr);
  pthread_mutex_lock(&h->guide.lock);
  fprintf(stderr,
          "haptic: guide: %" PRIu64 " ToolRole samples (%" PRIu64 " refused, %" PRIu64
          " not from the seat's server), %" PRIu64 " commands from other stations (%" PRIu64 " not finite), %" PRIu64
          " of ours skipped\n",
          h->guide.roles_received, h->guide.roles_rejected, h->guide.roles_ignored, h->guide.peer_samples,
          h->guide.bad_samples, h->guide.own_samples_skipped);
  pthread_mutex_unlock(&h->guide.lock);
  fprintf(
      stderr,
      "haptic: contact under delay: passivity observer max %.3g J over the late-model credit %.3g J (<= 0 passive), "
      "controller active %" PRIu64 " ticks; largest one-tick force change %.4f N; %" PRIu64
      " force cut(s) at a lost server, %" PRIu64 " server loss(es), %" PRIu64
      " stale-feedback episode(s); in contact %" PRIu64 " ticks re-anchored at the answered command (%" PRIu64
      " of them at the last placed lag), %" PRIu64 " plain plane\n",
      st->excess_max_j, st->credit_j, st->pc_ticks, st->step_max_n, st->cuts, st->server_lost, st->feedback_stale,
      st->reanchored_ticks, st->unplaced_ticks, st->plain_ticks);
  /* Contact under delay (issue 14): scripts and the link benchmark read these. */
  printf("CONTACT step_max_n=%.4f server_lost=%" PRIu64 " liveliness_blips=%" PRIu64 " feedback_stale=%" PRIu64
         " cuts=%" PRIu64 " controller_ticks=%" PRIu64 " guide_rtt_ms=%.1f energy_j=%.4g energy_max_j=%.4g"
         " stall_ticks=%" PRIu64 " stall_energy_j=%.4g energy_max_unstalled_j=%.4g credit_j=%.4g excess_max_j=%.4g\n",
         st->step_max_n, st->server_lost, st->liveliness_blips, st->feedback_stale, st->cuts, st->pc_ticks,
         st->guide_rtt_s * 1e3, st->energy_j, st->energy_max_j, st->stall_ticks, st->stall_energy_j,
         st->energy_max_unstalled_j, st->credit_j, st->excess_max_j);
  printf("SUMMARY ticks=%" PRIu64 " rate_hz=%.1f peak_force=%.4f contact_ticks=%" PRIu64 " latency_us_median=%.1f "
         "latency_us_p99=%.1f period_us_p99=%.1f jitter_us_p99=%.1f late_ticks=%" PRIu64 " guide_coupled_s=%.2f "
         "latency_us_mean=%.1f latency_samples=%zu\n",
         st->ticks, (double)st->ticks / st->elapsed_s, st->peak_force, st->contact_ticks, lat.median, lat.p99, per.p99,
         jitter_p99, st->late_ticks, guide_report_coupled_s(guide, 1.0 / o->rate), lat.mean, h->slot.nlatency);
  /* Whose feedback was believed (issue 15.2) and its order (14.2). */
  printf("FEEDBACK received=%" PRIu64 " ignored=%" PRIu64 " gate_dropped=%" PRIu64 " out_of_limits=%" PRIu64
         " stale=%" PRIu64 " servers_adopted=%" PRIu64 "\n",
         feedback, ignored, gate_dropped, beyond, stale, h->server.adopted);
}
