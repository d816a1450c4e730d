/* SPDX-License-Identifier: Apache-2.0 */
/* vsignal: the stop signals every long-running binary honours. Each main
 * keeps its own sig_atomic_t flag (no global state here) and passes the
 * handler that sets it; SIGINT and SIGTERM get it, with `flags` (e.g.
 * SA_RESETHAND so a second signal kills at once). */
#ifndef VISCERA_VSIGNAL_H
#define VISCERA_VSIGNAL_H

void vsignal_on_stop(void (*handler)(int), int flags);

/* The same for one other signal `sig` (e.g. SIGUSR1 with SA_RESTART). */
void vsignal_on(int sig, void (*handler)(int), int flags);

#endif
