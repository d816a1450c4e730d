/* SPDX-License-Identifier: Apache-2.0 */
/* The asset tool's exit statuses and its one way of reporting bad usage,
 * shared by asset_tool.c and asset_volume.c. */
#ifndef VISCERA_ASSET_USAGE_H
#define VISCERA_ASSET_USAGE_H

enum { EXIT_OK = 0, EXIT_ERROR = 1, EXIT_USAGE = 2, EXIT_PROBLEMS = 3 };

/* Prints "viscera-asset: ..." and the --help hint on stderr; returns
 * EXIT_USAGE. */
int bad_usage(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
