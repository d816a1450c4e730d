/* The asset tool's tetrahedral-mesh parts: `volume FILE` (what the server
 * reads from an organ's `volume:`) and the output format of `tet --out`.
 * Exit statuses are shared with asset_tool.c. */
#ifndef VISCERA_ASSET_VOLUME_H
#define VISCERA_ASSET_VOLUME_H

#include "volume_mesh.h"

enum { EXIT_OK = 0, EXIT_ERROR = 1, EXIT_USAGE = 2, EXIT_PROBLEMS = 3 };

/* Prints "viscera-asset: ..." and the --help hint; returns EXIT_USAGE. */
int bad_usage(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* The format for `tet --out out [--format name]`; -1 after a usage message. */
int asset_volume_format(const char *out, const char *name);
/* `volume FILE`: an exit status. */
int asset_volume_info(int argc, char **argv);

#endif
