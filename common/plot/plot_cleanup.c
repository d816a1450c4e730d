/* SPDX-License-Identifier: Apache-2.0 */
#include "plot/plot_cleanup.h"

#include <cairo.h>
#include <fontconfig/fontconfig.h>

void plot_cleanup(void) {
  /* cairo first: its font cache holds fontconfig patterns. */
  cairo_debug_reset_static_data();
  FcFini();
}
