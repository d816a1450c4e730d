/* SPDX-License-Identifier: Apache-2.0 */
/* plot_cleanup: releases what cairo and fontconfig cache for the life of
 * the process (font faces, patterns, configuration). Call once at exit,
 * after the last chart, from programs that draw charts: without it the
 * leak checker of the sanitizer build reports those caches as leaks. No
 * chart may be drawn afterwards. */
#ifndef VISCERA_PLOT_CLEANUP_H
#define VISCERA_PLOT_CLEANUP_H

void plot_cleanup(void);

#endif
