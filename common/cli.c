/* SPDX-License-Identifier: Apache-2.0 */
#include "cli.h"

#include <stdlib.h>
#include <string.h>

#ifndef VISCERA_VERSION
#define VISCERA_VERSION "unknown"
#endif

const char *cli_version(void) { return VISCERA_VERSION; }

int cli_parse_domain(const char *s) {
  char *end = NULL;
  long d = strtol(s, &end, 10);
  if (!s[0] || *end || d < 0 || d > 230) return -1;
  return (int)d;
}

int cli_env_domain(verr_t *err) {
  const char *env = getenv("VISCERA_DOMAIN");
  if (!env || !*env) return 0;
  int d = cli_parse_domain(env);
  if (d < 0) verr_set(err, "VISCERA_DOMAIN='%s' is not a domain id 0..230", env);
  return d;
}

/* The program's options followed by the common ones it takes. */
#define CLI_MAX_OPTIONS 48
static int build_options(const cli_spec_t *s, struct option *lo) {
  int n = 0;
  for (const struct option *o = s->options; o && o->name; o++) {
    if (n >= CLI_MAX_OPTIONS - 7) return -1;
    lo[n++] = *o;
  }
  if (s->common & CLI_DOMAIN) lo[n++] = (struct option){"domain", required_argument, 0, CLI_OPT_DOMAIN};
  if (s->common & CLI_DOMAIN) lo[n++] = (struct option){"insecure", no_argument, 0, CLI_OPT_INSECURE};
  if (s->common & CLI_PARTITION) lo[n++] = (struct option){"partition", required_argument, 0, CLI_OPT_PARTITION};
  if (s->common & CLI_QUIET) lo[n++] = (struct option){"quiet", no_argument, 0, CLI_OPT_QUIET};
  lo[n++] = (struct option){"help", no_argument, 0, CLI_OPT_HELP};
  lo[n++] = (struct option){"version", no_argument, 0, CLI_OPT_VERSION};
  lo[n] = (struct option){0, 0, 0, 0};
  return 0;
}

static int usage_status(const cli_spec_t *s) { return s->usage_status ? s->usage_status : 2; }

static int common_option(const cli_spec_t *s, const char *tag, int code, const char *arg, cli_common_t *c) {
  switch (code) {
  case CLI_OPT_DOMAIN:
    if ((c->domain = cli_parse_domain(arg)) < 0) {
      fprintf(stderr, "%s: ", tag);
      fprintf(stderr, s->domain_error ? s->domain_error : "--domain '%s' is not a domain id 0..230", arg);
      fprintf(stderr, "\n");
      return usage_status(s);
    }
    return 0;
  case CLI_OPT_PARTITION:
    if (s->partition_error && (!*arg || (s->partition_max && strlen(arg) >= s->partition_max))) {
      fprintf(stderr, "%s: %s\n", tag, s->partition_error);
      return usage_status(s);
    }
    c->partition = arg;
    return 0;
  case CLI_OPT_QUIET:
    c->quiet = 1;
    return 0;
  case CLI_OPT_INSECURE:
    /* Read where the participant is created (dds/vdds_config.h), which
     * this DDS-free layer does not reach: the environment carries it. */
    c->insecure = 1;
    if (setenv("VISCERA_INSECURE", "1", 1)) {
      fprintf(stderr, "%s: cannot set VISCERA_INSECURE\n", tag);
      return usage_status(s);
    }
    return 0;
  case CLI_OPT_HELP:
    s->usage(stdout);
    return 0;
  case CLI_OPT_VERSION:
    printf("%s %s\n", s->program, cli_version());
    return 0;
  default:
    s->usage(stderr);
    return usage_status(s);
  }
}

static int is_common(const cli_spec_t *s, int code) {
  return (code == CLI_OPT_DOMAIN && (s->common & CLI_DOMAIN)) ||
         (code == CLI_OPT_PARTITION && (s->common & CLI_PARTITION)) ||
         (code == CLI_OPT_QUIET && (s->common & CLI_QUIET)) || (code == CLI_OPT_INSECURE && (s->common & CLI_DOMAIN)) ||
         code == CLI_OPT_HELP || code == CLI_OPT_VERSION || code == '?' || code == ':';
}

int cli_parse(const cli_spec_t *s, int argc, char **argv, cli_common_t *c, void *ctx) {
  const char *tag = s->tag ? s->tag : s->program;
  if (s->common & CLI_DOMAIN_ENV) {
    verr_t err = {{0}};
    if ((c->domain = cli_env_domain(&err)) < 0) {
      fprintf(stderr, "%s: %s\n", tag, err.msg);
      return usage_status(s);
    }
  }
  struct option lo[CLI_MAX_OPTIONS];
  if (build_options(s, lo)) {
    fprintf(stderr, "%s: too many options\n", tag);
    return usage_status(s);
  }
  int code;
  while ((code = getopt_long(argc, argv, s->shortopts ? s->shortopts : "", lo, NULL)) != -1) {
    int rc = is_common(s, code) ? common_option(s, tag, code, optarg, c) : s->option(ctx, code, optarg);
    if (rc || code == CLI_OPT_HELP || code == CLI_OPT_VERSION) return rc;
  }
  return CLI_RUN;
}
