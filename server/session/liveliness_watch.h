/* SPDX-License-Identifier: Apache-2.0 */
/* liveliness_watch: which ToolCommand writers (haptic clients) have lost
 * their liveliness, handed from the DDS listener thread to the server loop.
 *
 * ToolCommand writers assert AUTOMATIC liveliness with a short lease
 * (vdds.h: VDDS_TOOL_LEASE_MS); when a client process dies its lease expires
 * and Cyclone calls the reader's liveliness-changed listener with that
 * writer's publication handle. The listener only queues the handle (it runs
 * on a DDS thread and the runtime is single-threaded); the loop drains the
 * queue every step and releases the tools that writer was driving.
 *
 * Confirmation: on a loaded machine the server's own receive thread can be
 * starved past the lease while the client is alive; the lease then expires
 * with the client's samples still waiting in the socket, and liveliness
 * returns as soon as they are read. So an entry is handed out only
 * LIVELINESS_CONFIRM_NS after the loss, and says whether the writer came
 * back meanwhile; the caller also keeps the tool if a command from it was
 * taken after the loss. Measured: without this, a load average of 11 on two
 * cores released a live client's tool within seconds; with a 20 ms window a
 * load of 21 (server steps stalling 350 ms) still did once. Such a release
 * is reported (CLIENT_LOST, then "haptic client back" with the next
 * command); the window trades that against detection time.
 *
 * The queue is bounded; on overflow the oldest entries are dropped and
 * counted, and the 0.5 s command timeout still releases those tools. */
#ifndef VISCERA_LIVELINESS_WATCH_H
#define VISCERA_LIVELINESS_WATCH_H

#include <dds/dds.h>
#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

#define LIVELINESS_WATCH_CAP 64
#define LIVELINESS_CONFIRM_NS 50000000ull /* 50 ms: lease + 50 ms is still well below the 0.5 s timeout */

typedef struct liveliness_lost {
  dds_instance_handle_t writer; /* publication handle of the lost writer */
  uint64_t mono_ns;             /* when the listener heard of it */
  int expired;                  /* 1: lease expired (process gone); 0: writer deleted (clean exit) */
  int regained;                 /* the same writer became alive again since */
} liveliness_lost_t;

typedef struct liveliness_watch {
  pthread_mutex_t lock;
  liveliness_lost_t q[LIVELINESS_WATCH_CAP];
  size_t head, n;
  uint64_t lost_total, regained_total, dropped;
} liveliness_watch_t;

void liveliness_watch_init(liveliness_watch_t *w);
void liveliness_watch_destroy(liveliness_watch_t *w);

/* Adds the liveliness-changed callback to listener l (argument: w). The
 * watch must outlive the reader the listener is attached to. */
void liveliness_watch_listen(liveliness_watch_t *w, dds_listener_t *l);

/* Records a status change; the listener calls this, tests may too. */
void liveliness_watch_note(liveliness_watch_t *w, const dds_liveliness_changed_status_t *st, uint64_t mono_ns);

/* Pops the oldest lost writer if it was lost at least confirm_ns before
 * now (monotonic ns); 1 when one was returned, 0 when none is due. */
int liveliness_watch_pop(liveliness_watch_t *w, uint64_t now, uint64_t confirm_ns, liveliness_lost_t *out);

#endif
