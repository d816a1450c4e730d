/* SPDX-License-Identifier: Apache-2.0 */
#include "rec_read.h"

#include <stdio.h>

int rec_read_topic(const char *tool, recfile_t *rf, const char *topic, const dds_topic_descriptor_t *desc,
                   rec_decode_cb cb, void *arg) {
  rec_decode_report_t rep;
  if (rec_decode_topic(rf, topic, desc, cb, arg, &rep) < 0) {
    fprintf(stderr, "%s: %s: out of memory\n", tool, topic);
    return 1;
  }
  uint64_t problems = rep.undecodable + rep.scan.invalid + rep.scan.damaged;
  if (problems)
    fprintf(stderr, "%s: %s: %llu sample(s) do not decode, %llu impossible row(s), %u damaged region(s)%s%s\n", tool,
            topic, (unsigned long long)rep.undecodable, (unsigned long long)rep.scan.invalid, rep.scan.damaged,
            rep.scan.first_error[0] ? ", first: " : "", rep.scan.first_error);
  return problems > 1000000 ? 1000000 : (int)problems;
}
