/* SPDX-License-Identifier: Apache-2.0 */
/* The shared command-line parser (common/cli.c): the common options with
 * their checks, a program's own options through its callback, --help and
 * --version answered with exit 0, bad values and unknown options refused
 * with the program's usage status, $VISCERA_DOMAIN as the default domain. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "cli.h"

typedef struct own {
  int widgets; /* --widgets N */
  int calls;   /* callback calls */
} own_t;

enum { O_WIDGETS = 300 };
static const struct option OWN[] = {{"widgets", required_argument, NULL, O_WIDGETS}, {NULL, 0, NULL, 0}};

static int own_option(void *ctx, int code, const char *arg) {
  own_t *o = ctx;
  o->calls++;
  if (code != O_WIDGETS) return 2;
  int n = atoi(arg);
  if (n < 1) return 7; /* the callback's own exit code passes through */
  o->widgets = n;
  return 0;
}

static void usage(FILE *f) { fprintf(f, "usage: test-prog [--widgets N]\n"); }

static const cli_spec_t SPEC = {.program = "test-prog",
                                .common = CLI_DOMAIN | CLI_PARTITION | CLI_QUIET,
                                .options = OWN,
                                .option = own_option,
                                .usage = usage,
                                .partition_error = "--partition: empty",
                                .partition_max = 8};

/* Parses a NULL-terminated argument list; stdout and stderr go to a scratch
 * file whose text is returned in out (so --version's line can be checked). */
static int parse(const cli_spec_t *spec, cli_common_t *c, own_t *o, char *out, size_t cap, ...) {
  char *argv[16];
  int argc = 0;
  argv[argc++] = "test-prog";
  va_list ap;
  va_start(ap, cap);
  const char *a;
  while ((a = va_arg(ap, const char *)) && argc < 15) argv[argc++] = (char *)a;
  va_end(ap);
  argv[argc] = NULL;
  fflush(stdout);
  fflush(stderr);
  FILE *tmp = tmpfile();
  int so = dup(1), se = dup(2);
  dup2(fileno(tmp), 1);
  dup2(fileno(tmp), 2);
  optind = 1;
  opterr = 1;
  int rc = cli_parse(spec, argc, argv, c, o);
  fflush(stdout);
  fflush(stderr);
  dup2(so, 1);
  dup2(se, 2);
  close(so);
  close(se);
  rewind(tmp);
  size_t n = fread(out, 1, cap - 1, tmp);
  out[n] = 0;
  fclose(tmp);
  return rc;
}

int main(void) {
  char out[4096];
  /* Domain strings. */
  CHECK(cli_parse_domain("0") == 0);
  CHECK(cli_parse_domain("230") == 230);
  CHECK(cli_parse_domain("231") == -1);
  CHECK(cli_parse_domain("-1") == -1);
  CHECK(cli_parse_domain("") == -1);
  CHECK(cli_parse_domain("7x") == -1);
  /* The environment's default domain. */
  verr_t err = {{0}};
  unsetenv("VISCERA_DOMAIN");
  CHECK(cli_env_domain(&err) == 0);
  setenv("VISCERA_DOMAIN", "42", 1);
  CHECK(cli_env_domain(&err) == 42);
  setenv("VISCERA_DOMAIN", "nope", 1);
  CHECK(cli_env_domain(&err) == -1 && strstr(err.msg, "VISCERA_DOMAIN='nope'"));
  unsetenv("VISCERA_DOMAIN");

  /* Common and own options together. */
  cli_common_t c = {.domain = 5};
  own_t o = {0};
  int rc = parse(&SPEC, &c, &o, out, sizeof out, "--domain", "12", "--partition", "lab/s1", "--quiet", "--widgets", "3",
                 (char *)NULL);
  CHECK(rc == CLI_RUN);
  CHECK(c.domain == 12 && c.partition && !strcmp(c.partition, "lab/s1") && c.quiet == 1);
  CHECK(o.widgets == 3 && o.calls == 1);
  /* Short forms of the common options. */
  c = (cli_common_t){.domain = 5};
  cli_spec_t shorts = SPEC;
  shorts.shortopts = "d:p:qh";
  CHECK(parse(&shorts, &c, &o, out, sizeof out, "-d", "9", "-p", "x", "-q", (char *)NULL) == CLI_RUN);
  CHECK(c.domain == 9 && !strcmp(c.partition, "x") && c.quiet);
  /* Defaults stay when an option is absent. */
  c = (cli_common_t){.domain = 5};
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, (char *)NULL) == CLI_RUN);
  CHECK(c.domain == 5 && c.partition == NULL && c.quiet == 0);
  /* CLI_DOMAIN_ENV: the default comes from the environment, a bad one is refused. */
  cli_spec_t env = SPEC;
  env.common |= CLI_DOMAIN_ENV;
  setenv("VISCERA_DOMAIN", "17", 1);
  c = (cli_common_t){.domain = 5};
  CHECK(parse(&env, &c, &o, out, sizeof out, (char *)NULL) == CLI_RUN && c.domain == 17);
  setenv("VISCERA_DOMAIN", "300", 1);
  CHECK(parse(&env, &c, &o, out, sizeof out, (char *)NULL) == 2 && strstr(out, "test-prog: VISCERA_DOMAIN='300'"));
  unsetenv("VISCERA_DOMAIN");

  /* --insecure (a DDS program: CLI_DOMAIN): flagged and passed on in the
   * environment, where the participant's start-up check reads it
   * (dds/vdds_config.h); a program without DDS does not take it. */
  unsetenv("VISCERA_INSECURE");
  c = (cli_common_t){.domain = 5};
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, (char *)NULL) == CLI_RUN && c.insecure == 0);
  CHECK(getenv("VISCERA_INSECURE") == NULL);
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, "--insecure", (char *)NULL) == CLI_RUN && c.insecure == 1);
  CHECK(getenv("VISCERA_INSECURE") && !strcmp(getenv("VISCERA_INSECURE"), "1"));
  unsetenv("VISCERA_INSECURE");
  cli_spec_t nodds = SPEC;
  nodds.common = CLI_QUIET;
  c = (cli_common_t){.domain = 5};
  CHECK(parse(&nodds, &c, &o, out, sizeof out, "--insecure", (char *)NULL) == 2 && getenv("VISCERA_INSECURE") == NULL);

  /* --help and --version: exit 0, on stdout. */
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, "--help", (char *)NULL) == 0 && strstr(out, "usage: test-prog"));
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, "--version", (char *)NULL) == 0);
  char want[64];
  snprintf(want, sizeof want, "test-prog %s\n", cli_version());
  CHECK(!strcmp(out, want));
  CHECK(strcmp(cli_version(), "unknown") != 0); /* the build passes the project version */

  /* Refusals: usage status 2 by default, the program's own when it says so. */
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, "--domain", "999", (char *)NULL) == 2);
  CHECK(strstr(out, "test-prog: --domain '999' is not a domain id 0..230") != NULL);
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, "--partition", "", (char *)NULL) == 2 &&
        strstr(out, "--partition: empty"));
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, "--partition", "much-too-long", (char *)NULL) == 2);
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, "--no-such-option", (char *)NULL) == 2 && strstr(out, "usage:"));
  CHECK(parse(&SPEC, &c, &o, out, sizeof out, "--widgets", "0", (char *)NULL) == 7);
  cli_spec_t one = SPEC;
  one.usage_status = 1;
  one.domain_error = "--domain '%s': expected an integer 0..230";
  CHECK(parse(&one, &c, &o, out, sizeof out, "--domain", "x", (char *)NULL) == 1);
  CHECK(strstr(out, "test-prog: --domain 'x': expected an integer 0..230") != NULL);
  /* A program without --partition does not take it. */
  cli_spec_t nopart = SPEC;
  nopart.common = CLI_DOMAIN;
  CHECK(parse(&nopart, &c, &o, out, sizeof out, "--partition", "x", (char *)NULL) == 2);
  return check_report("test_cli");
}
