/* vrt: make the calling thread a real-time thread (SCHED_FIFO, memory locked).
 *
 * Why: a 1 kHz loop (the haptic client's tick, the server's physics step)
 * sharing a small machine with many other processes misses its period
 * whenever the scheduler prefers them; CFS in particular lets a waking
 * process (a viewer receiving a mesh) preempt a running step. SCHED_FIFO
 * puts the loop ahead of every normal thread; locked pages keep page faults
 * out of it. Only the calling thread changes: DDS threads created before
 * stay at normal priority (threads it creates later inherit the policy).
 *
 * Safety: the loops that use this sleep until their next tick every period,
 * so they leave the CPU to the rest of the machine; the kernel's RT
 * throttling (sched_rt_runtime_us, by default 95 % of each second) bounds a
 * runaway FIFO thread anyway. Needs root or CAP_SYS_NICE (systemd:
 * AmbientCapabilities=CAP_SYS_NICE, or LimitRTPRIO=). */
#ifndef VISCERA_VRT_H
#define VISCERA_VRT_H

/* Parses an --rt-priority argument: 1..99. Returns it, or -1. */
int vrt_parse_priority(const char *s);

/* Puts the calling thread at SCHED_FIFO `priority` and locks the process's
 * memory. `who` prefixes the messages on stderr: a refusal (no privilege)
 * or a failed mlockall is a warning naming the reason, and the thread runs
 * on as it was; success prints one line unless quiet. Returns 0 when the
 * thread is real-time (memory locked or not), -1 when refused. */
int vrt_make_realtime(int priority, const char *who, int quiet);

#endif
