/* SPDX-License-Identifier: BSD-3-Clause */
/* A small persistent thread pool: started once, it runs numbered jobs on its threads and on
 * the caller's, and waits for them all. Internal to the library. */
#ifndef ISOPROP_POOL_H
#define ISOPROP_POOL_H

#include <pthread.h>
#include <stdatomic.h>

#include "isoprop/status.h"

typedef struct ip__pool ip__pool;

/* Starts a library thread running fn(arg) with every signal blocked (a signal for the process
 * then goes to the program's own threads). @return pthread_create()'s answer: 0 or an errno. */
int ip__thread_start(pthread_t *thread, void *(*fn)(void *), void *arg);

/* The work of one ip__pool_run(): called once for each index 0 .. jobs - 1, on any of the
 * pool's threads or the caller's, several at once. */
typedef void (*ip__pool_job)(void *user, unsigned index);

/* Starts a pool of `threads` threads counting the caller's (clamped to 1 .. IP_MAX_THREADS;
 * pass ip_thread_count()'s answer), that is threads - 1 helper threads, which wait for work
 * until ip__pool_destroy(), with every signal blocked. A pool of 1 starts none and runs every
 * job on the caller. Where a helper cannot be started the pool keeps those that did (the jobs
 * still all run, on fewer threads). *out is the caller's, released with ip__pool_destroy().
 * @return IP_OK or IP_ERR_NOMEM. */
ip_status ip__pool_create(unsigned threads, ip__pool **out, ip_error *err);

/* Stops and joins the helper threads and frees the pool; NULL is a no-op. Not during a run. */
void ip__pool_destroy(ip__pool *pool);

/* The threads that run jobs, the caller's included: 1 + the helpers that started. */
unsigned ip__pool_threads(const ip__pool *pool);

/* Runs fn(user, i) exactly once for each i in 0 .. jobs - 1, on the helpers and the calling
 * thread, and returns when every call has returned; what the calls wrote is then visible to
 * the caller. Indices are taken in increasing order, each by the first free thread, so a job
 * never runs on two threads at once but its thread varies. One run at a time per pool, never
 * from inside a job. jobs == 0 does nothing. */
void ip__pool_run(ip__pool *pool, unsigned jobs, ip__pool_job fn, void *user);

/* How long a thread about to sleep on a condition first spins on it (seconds). Waking a
 * sleeping helper costs a step about 19 us on a 2-core virtual machine (bench_pool: 18.65 us
 * a step sleeping, 0.93 us spinning), as long as a small engine step's tail; a short spin
 * takes the news at once, for at most this much CPU per wait. */
#define IP_SPIN_SECONDS 50e-6

/* How long the pool's threads, and work that waits on them, spin before sleeping (seconds):
 * IP_SPIN_SECONDS, or 0 when the pool has more threads than the machine has cores (a spinner
 * would hold the core that the thread it waits for needs). */
double ip__pool_spin_seconds(const ip__pool *pool);

/* Spins (with the processor's pause hint) while *word == seen, for up to `seconds`. `held`: a
 * mutex the caller holds, let go while spinning and taken again before returning (the word's
 * writers may need it); NULL for none. @return 1 when the word changed, 0 when the time ran
 * out (at once for seconds <= 0). */
int ip__spin_while(const atomic_uint *word, unsigned seen, double seconds, pthread_mutex_t *held);

#endif
