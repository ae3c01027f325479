/* SPDX-License-Identifier: BSD-3-Clause */
/* bench_pool: what it costs to hand a step to worker threads, as the engine does once per
 * ip_engine_step() (every viewer frame): starting and joining threads for each step (how the
 * library worked before the pool) against waking the threads of a pool started once.
 *
 * Each step runs `threads` jobs that only wait for each other, one per thread, so the time is
 * the dispatch alone: from the step's start until every thread has run its job and returned.
 * The two ways alternate, round after round; the figures are per step, in microseconds, the
 * median of the rounds and their range. A benchmark, not a test: every figure depends on the
 * machine and on what else runs on it.
 */
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "isoprop/system.h"
#include "pool.h"

static const char usage[] =
    "usage: bench_pool [--threads N] [--steps N] [--rounds N]\n"
    "Per-step cost of starting threads for each step against a persistent pool.\n"
    "  --threads N   threads per step, the caller's included (default: all cores)\n"
    "  --steps N     steps per timing (default 2000)\n"
    "  --rounds N    timings of each way, interleaved (default 9)\n";

/* The jobs of a step meet before they return: each waits until all `threads` have started,
 * so a step lasts until every thread runs it, however little the work (otherwise the caller
 * could do every job alone before a helper woke). */
static atomic_uint jobs_done;

static void meet_job(void *user, unsigned index)
{
    unsigned until = *(const unsigned *)user;
    (void)index;
    atomic_fetch_add(&jobs_done, 1);
    while (atomic_load(&jobs_done) < until)
        sched_yield();
}

static void *meet_thread(void *user)
{
    meet_job(user, 0);
    return NULL;
}

/* The old way: threads - 1 threads started for the step, the caller's share, the joins. */
static void step_with_new_threads(unsigned threads, unsigned *until)
{
    pthread_t tids[IP_MAX_THREADS];
    unsigned started = 0;
    *until = atomic_load(&jobs_done) + threads;
    for (unsigned t = 1; t < threads; t++)
        if (pthread_create(&tids[started], NULL, meet_thread, until) == 0)
            started++;
    meet_job(until, 0);
    for (unsigned t = 0; t < started; t++)
        pthread_join(tids[t], NULL);
}

static void step_on_pool(ip__pool *pool, unsigned threads, unsigned *until)
{
    *until = atomic_load(&jobs_done) + threads;
    ip__pool_run(pool, threads, meet_job, until);
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
    unsigned threads = 0, steps = 2000, rounds = 9, until = 0;
    for (int i = 1; i < argc; i++) {
        unsigned *to = !strcmp(argv[i], "--threads")  ? &threads
                       : !strcmp(argv[i], "--steps")  ? &steps
                       : !strcmp(argv[i], "--rounds") ? &rounds
                                                      : NULL;
        if (!to || i + 1 >= argc) {
            fputs(usage, stderr);
            return 2;
        }
        *to = (unsigned)strtoul(argv[++i], NULL, 10);
    }
    if (steps == 0 || rounds == 0) {
        fputs(usage, stderr);
        return 2;
    }
    threads = ip_thread_count(threads);
    ip__pool *pool;
    ip_error err;
    if (ip__pool_create(threads, &pool, &err) != IP_OK) {
        fprintf(stderr, "bench_pool: %s\n", err.message);
        return 1;
    }
    double *created = calloc(rounds, sizeof *created), *pooled = calloc(rounds, sizeof *pooled);
    if (!created || !pooled)
        return 1;
    for (unsigned r = 0; r < rounds; r++) {
        double t0 = ip_now_seconds();
        for (unsigned s = 0; s < steps; s++)
            step_with_new_threads(threads, &until);
        double t1 = ip_now_seconds();
        for (unsigned s = 0; s < steps; s++)
            step_on_pool(pool, threads, &until);
        double t2 = ip_now_seconds();
        created[r] = (t1 - t0) / steps * 1e6;
        pooled[r] = (t2 - t1) / steps * 1e6;
    }
    ip__pool_destroy(pool);
    unsigned expect = 2 * rounds * steps * threads;
    if (atomic_load(&jobs_done) != expect) {
        fprintf(stderr, "bench_pool: %u jobs ran, %u expected\n", atomic_load(&jobs_done), expect);
        return 1;
    }
    qsort(created, rounds, sizeof *created, compare_double);
    qsort(pooled, rounds, sizeof *pooled, compare_double);
    printf("| way | threads | steps x rounds | us per step: median [min-max] |\n");
    printf("| --- | --- | --- | --- |\n");
    printf("| threads started per step | %u | %u x %u | %.2f [%.2f-%.2f] |\n", threads, steps,
           rounds, created[rounds / 2], created[0], created[rounds - 1]);
    printf("| pool started once | %u | %u x %u | %.2f [%.2f-%.2f] |\n", threads, steps, rounds,
           pooled[rounds / 2], pooled[0], pooled[rounds - 1]);
    free(created);
    free(pooled);
    return 0;
}
