/* SPDX-License-Identifier: Apache-2.0 */
/* check.h: the few assertion macros the unit tests share. A failed check
 * prints file:line and the values, and the test exits non-zero at the end. */
#ifndef VISCERA_CHECK_H
#define VISCERA_CHECK_H

#include <math.h>
#include <stdio.h>

static int check_failures = 0;
static int check_count = 0;

#define CHECK(cond)                                                                                                    \
  do {                                                                                                                 \
    check_count++;                                                                                                     \
    if (!(cond)) {                                                                                                     \
      check_failures++;                                                                                                \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);                                        \
    }                                                                                                                  \
  } while (0)

#define CHECK_NEAR(a, b, tol)                                                                                          \
  do {                                                                                                                 \
    double check_a_ = (a), check_b_ = (b), check_t_ = (tol);                                                           \
    check_count++;                                                                                                     \
    if (!(fabs(check_a_ - check_b_) <= check_t_)) {                                                                    \
      check_failures++;                                                                                                \
      fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.9g, %s = %.9g, tol %.3g\n", __FILE__, __LINE__, #a, check_a_, \
              #b, check_b_, check_t_);                                                                                 \
    }                                                                                                                  \
  } while (0)

/* Call at the end of main: prints the tally and returns the exit code. */
static inline int check_report(const char *name) {
  printf("%s: %d checks, %d failed\n", name, check_count, check_failures);
  return check_failures ? 1 : 0;
}

#endif
