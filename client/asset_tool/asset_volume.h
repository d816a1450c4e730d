/* SPDX-License-Identifier: Apache-2.0 */
/* The asset tool's tetrahedral-mesh parts: `volume FILE` (what the server
 * reads from an organ's `volume:`) and the output format of `tet --out`.
 * Exit statuses: asset_usage.h. */
#ifndef VISCERA_ASSET_VOLUME_H
#define VISCERA_ASSET_VOLUME_H

#include "asset_usage.h"
#include "volume_mesh.h"

/* The format for `tet --out out [--format name]`; -1 after a usage message. */
int asset_volume_format(const char *out, const char *name);
/* `volume FILE`: an exit status. */
int asset_volume_info(int argc, char **argv);

#endif
