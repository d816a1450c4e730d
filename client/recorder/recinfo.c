/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-recinfo: what is in a session recording, and is it sane.
 *
 * Prints the session metadata and one line per topic (samples by kind,
 * bytes, first/last source timestamp, rate). --check-monotonic verifies
 * that each writer's data-sample source timestamps never decrease in
 * insertion order, which is what replay relies on. Damaged files are read as far as they
 * can be and reported; the exit status says what happened. */
#include <stdio.h>

#include "cli.h"
#include "recinfo_run.h"

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-recinfo FILE.db [--topic NAME] [--check-monotonic]\n"
             "       viscera-recinfo FILE.db --export mcap [--foxglove-scene] OUT.mcap\n"
             "       viscera-recinfo FILE.db --export csv|jsonl --topic NAME OUT|-\n"
             "Prints the session metadata of a viscera recording and a table per topic:\n"
             "samples (data/dispose/unregister), CDR bytes, first and last source\n"
             "timestamp (UTC) and mean rate of data samples.\n"
             "\n"
             "  -t, --topic NAME        only this topic\n"
             "  -m, --check-monotonic   fail if, for any writer of a topic, the source\n"
             "                          timestamps of its data samples decrease in the\n"
             "                          order they were stored (dispose/unregister rows\n"
             "                          are not checked: when Cyclone derives them from a\n"
             "                          writer leaving they carry the instance's last\n"
             "                          update time)\n"
             "  -e, --export FORMAT     write the recording in another format instead:\n"
             "                          mcap   every topic, schemas as OMG IDL (from the recorded type\n"
             "                                 information), messages as CDR (XCDR2 samples re-encoded\n"
             "                                 as XCDR1, which every CDR reader takes), times = source time\n"
             "                                 (opens in Foxglove and any MCAP reader)\n"
             "                          csv    one topic (--topic), decoded fields, one row per sample\n"
             "                          jsonl  one topic, one JSON object per sample\n"
             "      --foxglove-scene    with mcap: the organ meshes also as Foxglove scene primitives\n"
             "                          (channel /viscera/scene, foxglove.SceneUpdate in JSON, 10 Hz)\n"
             "  -q, --quiet             no summary line after an export\n"
             "  -h, --help              this text\n"
             "      --version           print the version and exit\n"
             "\n"
             "Exit status: 0 fine; 1 missing, unreadable, not a recording, or damaged (what\n"
             "could be salvaged is still printed); 2 usage error; 3 timestamps not monotonic.\n");
}

enum { OPT_TOPIC = 't', OPT_CHECK_MONOTONIC = 'm', OPT_EXPORT = 'e', OPT_SCENE = 1000 };

static int on_option(void *ctx, int code, const char *arg) {
  recinfo_options_t *o = ctx;
  switch (code) {
  case OPT_TOPIC:
    o->topic = arg;
    return EXIT_OK;
  case OPT_CHECK_MONOTONIC:
    o->check_mono = true;
    return EXIT_OK;
  case OPT_EXPORT:
    o->export_format = export_format_parse(arg);
    if (o->export_format == EXPORT_NONE) {
      fprintf(stderr, "recinfo: --export '%s': expected mcap, csv or jsonl\n", arg);
      return EXIT_USAGE;
    }
    return EXIT_OK;
  case OPT_SCENE:
    o->foxglove_scene = true;
    return EXIT_OK;
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

int main(int argc, char **argv) {
  static const struct option longopts[] = {
      {"topic", required_argument, 0, OPT_TOPIC},
      {"check-monotonic", no_argument, 0, OPT_CHECK_MONOTONIC},
      {"export", required_argument, 0, OPT_EXPORT},
      {"foxglove-scene", no_argument, 0, OPT_SCENE},
      {0, 0, 0, 0},
  };
  const cli_spec_t spec = {.program = "viscera-recinfo",
                           .tag = "recinfo",
                           .common = CLI_QUIET,
                           .shortopts = "t:me:qh",
                           .options = longopts,
                           .option = on_option,
                           .usage = usage};
  recinfo_options_t o = {0};
  cli_common_t common = {0};
  int rc = cli_parse(&spec, argc, argv, &common, &o);
  if (rc != CLI_RUN) return rc;
  int want = o.export_format == EXPORT_NONE ? 1 : 2; /* an export names its output too */
  if (argc - optind != want) {
    fprintf(stderr, "recinfo: %s\n",
            optind >= argc ? "a recording file is required"
            : want == 2    ? "--export needs the recording and the output file"
                           : "only one file, please");
    usage(stderr);
    return EXIT_USAGE;
  }
  o.path = argv[optind];
  o.export_out = want == 2 ? argv[optind + 1] : NULL;
  o.quiet = common.quiet;
  return recinfo_run(&o);
}
