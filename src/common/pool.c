/* SPDX-License-Identifier: BSD-3-Clause */
/* The library's thread pool: helpers started once, woken for each run by a generation
 * counter, taking job indices under one mutex. Jobs are coarse (a worker's share of a step,
 * a layer or a group of planes), so one lock per job costs nothing. */
#include <pthread.h>
#include <signal.h>
#include <stdlib.h>

#include "internal.h"
#include "isoprop/system.h"
#include "pool.h"

/* The processor's hint that this thread spins (it then leaves the loop without a pipeline
 * flush, and lends the core to its other hardware thread). */
static inline void relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}

/* ip__spin_while() without the mutex. */
static int spin(const atomic_uint *word, unsigned seen, double seconds)
{
    if (!(seconds > 0))
        return atomic_load_explicit(word, memory_order_acquire) != seen;
    double until = 0;
    for (unsigned i = 1;; i++) {
        if (atomic_load_explicit(word, memory_order_acquire) != seen)
            return 1;
        relax();
        if (i % 64 == 0) { /* the clock now and then: it costs more than a pause */
            double now = ip_now_seconds();
            if (until == 0)
                until = now + seconds;
            else if (now >= until)
                return 0;
        }
    }
}

int ip__spin_while(const atomic_uint *word, unsigned seen, double seconds, pthread_mutex_t *held)
{
    if (held)
        pthread_mutex_unlock(held);
    int changed = spin(word, seen, seconds);
    if (held)
        pthread_mutex_lock(held);
    return changed;
}

struct ip__pool {
    pthread_mutex_t lock;
    pthread_cond_t work_ready; /* helpers: a new run (generation changed) or stop */
    pthread_cond_t work_done;  /* the caller: done reached jobs */
    unsigned helpers;          /* helper threads started */
    pthread_t *tids;
    /* The current run, guarded by lock. */
    atomic_uint generation; /* runs started so far (read unlocked to spin on) */
    ip__pool_job fn;
    void *user;
    unsigned jobs, next;
    atomic_uint done; /* (read unlocked to spin on) */
    int stop;
    double spin; /* ip__pool_spin_seconds() */
};

/* Runs jobs of the current run until none is left to take; called and returns with the lock
 * held. */
static void take_jobs(ip__pool *p)
{
    while (p->next < p->jobs) {
        unsigned i = p->next++;
        ip__pool_job fn = p->fn;
        void *user = p->user;
        pthread_mutex_unlock(&p->lock);
        fn(user, i);
        pthread_mutex_lock(&p->lock);
        if (atomic_fetch_add(&p->done, 1) + 1 == p->jobs)
            pthread_cond_signal(&p->work_done);
    }
}

static void *helper(void *arg)
{
    ip__pool *p = arg;
    unsigned seen = 0; /* not p->generation: a run may start before this thread does */
    pthread_mutex_lock(&p->lock);
    for (;;) {
        /* a short spin first: the next run often comes at once (an engine's steps) */
        if (!p->stop && atomic_load(&p->generation) == seen)
            ip__spin_while(&p->generation, seen, p->spin, &p->lock);
        while (!p->stop && atomic_load(&p->generation) == seen)
            pthread_cond_wait(&p->work_ready, &p->lock);
        if (p->stop)
            break;
        seen = atomic_load(&p->generation);
        take_jobs(p);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

int ip__thread_start(pthread_t *thread, void *(*fn)(void *), void *arg)
{
    /* Every signal blocked, so that a signal for the process (Ctrl-C) goes to the program's
     * own threads, which may be waiting for it, and never to a thread of the library. */
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old);
    int rc = pthread_create(thread, NULL, fn, arg);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return rc;
}

ip_status ip__pool_create(unsigned threads, ip__pool **out, ip_error *err)
{
    if (threads < 1)
        threads = 1;
    if (threads > IP_MAX_THREADS)
        threads = IP_MAX_THREADS;
    ip__pool *p = calloc(1, sizeof *p);
    if (!p || (threads > 1 && !(p->tids = calloc(threads - 1, sizeof *p->tids)))) {
        free(p);
        return ip__fail(err, IP_ERR_NOMEM, "out of memory");
    }
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->work_ready, NULL);
    pthread_cond_init(&p->work_done, NULL);
    p->spin = threads <= ip_thread_count(0) ? IP_SPIN_SECONDS : 0;
    for (unsigned t = 0; t + 1 < threads; t++)
        if (ip__thread_start(&p->tids[p->helpers], helper, p) == 0)
            p->helpers++;
    *out = p;
    return IP_OK;
}

void ip__pool_destroy(ip__pool *p)
{
    if (!p)
        return;
    pthread_mutex_lock(&p->lock);
    p->stop = 1;
    pthread_cond_broadcast(&p->work_ready);
    pthread_mutex_unlock(&p->lock);
    for (unsigned t = 0; t < p->helpers; t++)
        pthread_join(p->tids[t], NULL);
    pthread_cond_destroy(&p->work_done);
    pthread_cond_destroy(&p->work_ready);
    pthread_mutex_destroy(&p->lock);
    free(p->tids);
    free(p);
}

double ip__pool_spin_seconds(const ip__pool *p)
{
    return p->spin;
}

unsigned ip__pool_threads(const ip__pool *p)
{
    return 1 + p->helpers;
}

void ip__pool_run(ip__pool *p, unsigned jobs, ip__pool_job fn, void *user)
{
    if (p->helpers == 0 || jobs == 1) { /* nobody to share with: no locks, no wake-ups */
        for (unsigned i = 0; i < jobs; i++)
            fn(user, i);
        return;
    }
    if (jobs == 0)
        return;
    pthread_mutex_lock(&p->lock);
    p->fn = fn;
    p->user = user;
    p->jobs = jobs;
    p->next = 0;
    atomic_store(&p->done, 0);
    atomic_fetch_add(&p->generation, 1);
    pthread_cond_broadcast(&p->work_ready);
    take_jobs(p);
    unsigned done = atomic_load(&p->done); /* the helpers' last jobs: spin a little, then sleep */
    while (done < jobs && ip__spin_while(&p->done, done, p->spin, &p->lock))
        done = atomic_load(&p->done);
    while (atomic_load(&p->done) < p->jobs)
        pthread_cond_wait(&p->work_done, &p->lock);
    pthread_mutex_unlock(&p->lock);
}
