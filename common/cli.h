/* SPDX-License-Identifier: Apache-2.0 */
/* cli: the command-line options every viscera program shares, parsed in one
 * place: --domain N, --partition P, --quiet, --insecure, -h/--help and
 * --version.
 *
 * A program describes itself in a cli_spec_t (its name, which common
 * options it takes, its own getopt_long options and a callback for them,
 * its usage text) and calls cli_parse(). The common options are handled
 * here with the same checks everywhere; a program's own options go to its
 * callback. No DDS: the domain is a number 0..230 here, the program hands it
 * to its DDS layer. */
#ifndef VISCERA_CLI_H
#define VISCERA_CLI_H

#include <getopt.h>
#include <stdio.h>

#include "verr.h"

/* cli_parse() result: go on and run (anything else is the exit code). */
#define CLI_RUN (-1)

/* Which common options a program takes (cli_spec_t.common). -h/--help and
 * --version are always taken. */
enum {
  CLI_DOMAIN = 1 << 0,     /* --domain N, N in 0..230; and --insecure (a DDS program) */
  CLI_DOMAIN_ENV = 1 << 1, /* the default domain is $VISCERA_DOMAIN (else 0) */
  CLI_PARTITION = 1 << 2,  /* --partition P */
  CLI_QUIET = 1 << 3,      /* --quiet */
};

/* getopt codes of the common options. A program's own options use other
 * codes; 'd', 'p', 'q' and 'h' so a program whose short-option string lists
 * "d:", "p:", "q" or "h" also takes -d N, -p P, -q and -h. */
enum {
  CLI_OPT_DOMAIN = 'd',
  CLI_OPT_PARTITION = 'p',
  CLI_OPT_QUIET = 'q',
  CLI_OPT_HELP = 'h',
  CLI_OPT_VERSION = 0x7f00,
  CLI_OPT_INSECURE = 0x7f01,
};

/* --insecure: run on a non-loopback Cyclone configuration without DDS
 * Security, which a DDS program otherwise refuses (dds/vdds_config.h). It
 * sets VISCERA_INSECURE=1 in the process's environment, where the check at
 * participant creation reads it. Its line for a program's --help: */
#define CLI_HELP_INSECURE                                                                                              \
  "  --insecure          allow a non-loopback CYCLONEDDS_URI without DDS Security (warns;\n"                           \
  "                      same as VISCERA_INSECURE=1); refused without it\n"

/* The values of the common options. */
typedef struct cli_common {
  int domain;            /* 0..230; the default given to cli_parse unless CLI_DOMAIN_ENV */
  const char *partition; /* NULL when --partition was not given (or the default given) */
  int quiet;             /* --quiet given */
  int insecure;          /* --insecure given (VISCERA_INSECURE=1 set) */
} cli_common_t;

/* A program's own option: `code` is the getopt code of its struct option,
 * `arg` its value (NULL for a flag). Returns 0, or the exit code after
 * printing why the value is refused. */
typedef int (*cli_option_fn)(void *ctx, int code, const char *arg);

typedef struct cli_spec {
  const char *program;          /* "viscera-server": --version prints "viscera-server VERSION" */
  const char *tag;              /* prefix of messages ("viscera-server", "recorder"); NULL: program */
  unsigned common;              /* CLI_DOMAIN | CLI_DOMAIN_ENV | CLI_PARTITION | CLI_QUIET */
  const char *shortopts;        /* getopt short options ("s:d:p:qh"; "+..." stops at the first operand) */
  const struct option *options; /* the program's own long options, {0}-terminated; NULL: none */
  cli_option_fn option;         /* called for each of them; NULL: none */
  void (*usage)(FILE *f);       /* the help text: stdout for --help, stderr after a usage error */
  const char *domain_error;     /* a bad --domain, after "TAG: " (one %s, the value); NULL: the default */
  const char *partition_error;  /* non-NULL: an empty --partition is refused with "TAG: " this */
  unsigned partition_max;       /* > 0: a --partition of this many bytes or more is refused too */
  int usage_status;             /* exit code of a usage error (bad value, unknown option); 0: 2 */
} cli_spec_t;

/* Parses argv with getopt_long (optind left at the first operand). `c`
 * holds the defaults on entry. Returns CLI_RUN, 0 after --help or --version
 * (printed on stdout), or the usage status (2 unless the spec says otherwise)
 * after a message on stderr (bad value, unknown option, bad $VISCERA_DOMAIN),
 * or the exit code the option callback gave. */
int cli_parse(const cli_spec_t *spec, int argc, char **argv, cli_common_t *c, void *ctx);

/* A domain id string 0..230; -1 on bad input. */
int cli_parse_domain(const char *s);
/* $VISCERA_DOMAIN if set and non-empty, else 0; -1 with err when the
 * variable is not a domain id. */
int cli_env_domain(verr_t *err);
/* The project version: CMake project(VERSION) plus git describe when the
 * build had git, "0.1.0 (git a69fab4)" (cmake/version.cmake). */
const char *cli_version(void);

#endif
