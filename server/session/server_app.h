/* SPDX-License-Identifier: Apache-2.0 */
/* server_app: what viscera-server does once its command line is parsed
 * (session/main.c): load the scene, then either check it (--check) or run
 * the session until a signal or --duration, and print the summary.
 * With --seats N the process runs N sessions of the scene, one per
 * partition P/seatKK..P/seat(K+N-1) (K: --first-seat, default 1; two
 * digits, as deploy/lab.sh and deploy/pki.sh name seats), stepped by
 * --seat-threads physics threads (default: one per online CPU, at most one
 * per seat), each stepping a contiguous group of seats every tick
 * (seat_group.h; DDS threads are shared by the process's participants).
 * Why: several seats' servers on one core run each step after the others
 * have run; as separate processes, or as a thread per seat, every step
 * also starts after other processes had the core (docs/numerics.md §11.3
 * measures what each costs). A seat whose set-up fails is reported at once
 * and the others keep serving; the summaries follow per seat at the end,
 * each headed by its partition.
 * Files: with --seats, --checkpoint PATH and --final-mesh PATH name each
 * seat's own file PATH.seatKK (a crashed process's seats each resume from
 * their own state). */
#ifndef VISCERA_SESSION_SERVER_APP_H
#define VISCERA_SESSION_SERVER_APP_H

#include "session/server.h"

enum { SERVER_APP_MAX_SEATS = 32, SERVER_APP_PATH_MAX = 1024 };

typedef struct server_app_options {
  const char *scene_path; /* --scene FILE */
  int seats;              /* --seats N: 1..SERVER_APP_MAX_SEATS; 0: not given (one session on the partition as given) */
  int first_seat;         /* --first-seat K: the first seat's number (seatKK), 1..99 with K + N - 1 <= 99 */
  int seat_threads;       /* --seat-threads K: with --seats, K physics threads each stepping a group of seats
                             (seat_group.h); 0: one per online CPU, at most one per seat */
  int check_only;         /* --check */
  int cpu_wake_us;        /* --cpu-wake-latency US (cpu_wake.h, held by main); -1: not asked */
  cpu_pin_t physics_cpus; /* --physics-cpus LIST (count 0: not given); opts.physics_cpus points here */
  server_opts_t opts;     /* everything server_run (seat_group.h) takes */
} server_app_options_t;

/* Returns the exit code: 0 done, 1 scene or runtime error (with seats: any
 * seat's). */
int server_app_run(const server_app_options_t *o);

#endif
