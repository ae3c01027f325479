/* SPDX-License-Identifier: BSD-3-Clause */
/* isowall's watchdog: a wall whose process stops answering (stopped, its node gone, its link
 * cut) ends with an error naming it instead of hanging.
 *
 * Every process runs a helper thread that sends a heartbeat, a small message on a communicator
 * of its own, every quarter of the timeout (at most every second), and receives the others'
 * heartbeats, in a star: process 0 hears from every process and every process from process 0.
 * A process is silent when nothing has come from it for the timeout; while it computes (a long
 * unit, a large tile, a PNG being written), its helper thread still answers, so only a process
 * that does not run at all, or whose messages do not arrive, is ever silent. Process 0 names
 * every silent process; a silent process 0 is named by process 1 (by the others after twice
 * the timeout, in case process 1 is silent too). The one that names them prints one line,
 * what its own main thread was doing, and ends the job with MPI_Abort, wherever the other
 * threads are blocked: a barrier, a collective, a receive, a lock of the window of shares.
 * A process ends its heartbeats with a last message once its work is done, and its watchdog
 * ends when every process it hears from has sent that (so a process that stops after its
 * work, before the others are done, is named too); only MPI_Finalize is then left unwatched.
 *
 * The helper thread calls MPI beside the main thread: the watchdog needs MPI_THREAD_MULTIPLE.
 */
#ifndef ISOWALL_WATCH_H
#define ISOWALL_WATCH_H

/* Starts the watchdog of `timeout` seconds (> 0) on every process of MPI_COMM_WORLD (every
 * process must call it: it duplicates the communicator). Does nothing on one process. When
 * the thread cannot start (no memory, no thread), prints why and ends the job (MPI_Abort). */
void wall_watch_start(const char *program, double timeout);

/* Says what this process's main thread does now, for the watchdog's line when this process is
 * the one that names a silent process ("waiting for tile 3 from rank 2 at the composite");
 * nothing when no watchdog runs. */
void wall_watch_stage(const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* Ends this process's heartbeats (its work is done) and returns once every process it hears
 * from has ended its own, still naming a process that goes silent meanwhile. Does nothing when
 * no watchdog runs. */
void wall_watch_stop(void);

#endif
