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
             "  -h, --help              this text\n"
             "      --version           print the version and exit\n"
             "\n"
             "Exit status: 0 fine; 1 missing, unreadable, not a recording, or damaged (what\n"
             "could be salvaged is still printed); 2 usage error; 3 timestamps not monotonic.\n");
}

enum { OPT_TOPIC = 't', OPT_CHECK_MONOTONIC = 'm' };

static int on_option(void *ctx, int code, const char *arg) {
  recinfo_options_t *o = ctx;
  switch (code) {
  case OPT_TOPIC:
    o->topic = arg;
    return EXIT_OK;
  case OPT_CHECK_MONOTONIC:
    o->check_mono = true;
    return EXIT_OK;
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

int main(int argc, char **argv) {
  static const struct option longopts[] = {
      {"topic", required_argument, 0, OPT_TOPIC},
      {"check-monotonic", no_argument, 0, OPT_CHECK_MONOTONIC},
      {0, 0, 0, 0},
  };
  const cli_spec_t spec = {.program = "viscera-recinfo",
                           .tag = "recinfo",
                           .shortopts = "t:mh",
                           .options = longopts,
                           .option = on_option,
                           .usage = usage};
  recinfo_options_t o = {0};
  cli_common_t common = {0};
  int rc = cli_parse(&spec, argc, argv, &common, &o);
  if (rc != CLI_RUN) return rc;
  if (optind != argc - 1) {
    fprintf(stderr, "recinfo: %s\n", optind >= argc ? "a recording file is required" : "only one file, please");
    usage(stderr);
    return EXIT_USAGE;
  }
  o.path = argv[optind];
  return recinfo_run(&o);
}
