/* SPDX-License-Identifier: BSD-3-Clause */
/* The thread pool: every job runs exactly once per run, runs can follow each other on one
 * pool, the helpers really run jobs at the same time as the caller (with signals blocked), a
 * pool of 1 runs on the caller, and a pool may be destroyed without ever running. The spin
 * before a sleep: it sees another thread's change, gives up when its time is out, and is off
 * for a pool with more threads than the machine has cores. */
#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <time.h>

#include "check.h"
#include "isoprop/system.h"
#include "pool.h"

#define MAX_JOBS 5000

/* Counts the calls of each index; `plain` is written without atomics, so that a run which did
 * not wait for its jobs, or did not publish their writes, shows as a wrong value (or a
 * ThreadSanitizer report). */
typedef struct tally {
    atomic_uint calls[MAX_JOBS];
    unsigned plain[MAX_JOBS];
    atomic_uint total;
} tally;

static void count_job(void *user, unsigned index)
{
    tally *t = user;
    atomic_fetch_add(&t->calls[index], 1);
    atomic_fetch_add(&t->total, 1);
    t->plain[index] = index * 3 + 1;
}

/* Runs `jobs` jobs on `pool` and checks each ran once and its write is seen. */
static void check_run(ip__pool *pool, tally *t, unsigned jobs)
{
    for (unsigned i = 0; i < MAX_JOBS; i++) {
        atomic_store(&t->calls[i], 0);
        t->plain[i] = 0;
    }
    atomic_store(&t->total, 0);
    ip__pool_run(pool, jobs, count_job, t);
    unsigned wrong = 0;
    for (unsigned i = 0; i < MAX_JOBS; i++) {
        unsigned want = i < jobs ? 1u : 0u;
        if (atomic_load(&t->calls[i]) != want || t->plain[i] != (want ? i * 3 + 1 : 0))
            wrong++;
    }
    CHECK_MSG(wrong == 0 && atomic_load(&t->total) == jobs,
              "%u jobs on %u threads: %u indices wrong, %u calls", jobs, ip__pool_threads(pool),
              wrong, atomic_load(&t->total));
}

/* A rendezvous: each job waits until `expected` jobs have arrived, then notes its thread.
 * It completes only if that many jobs run at the same time, on as many threads. */
typedef struct meeting {
    pthread_mutex_t lock;
    pthread_cond_t all_here;
    unsigned expected, arrived;
    int gave_up;
    pthread_t who[IP_MAX_THREADS];
    int sigint_blocked[IP_MAX_THREADS];
} meeting;

static void meet_job(void *user, unsigned index)
{
    meeting *m = user;
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += 30; /* a broken pool fails the check instead of hanging the test */
    sigset_t mask;
    pthread_sigmask(SIG_BLOCK, NULL, &mask);
    pthread_mutex_lock(&m->lock);
    m->who[index] = pthread_self();
    m->sigint_blocked[index] = sigismember(&mask, SIGINT) == 1;
    if (++m->arrived == m->expected)
        pthread_cond_broadcast(&m->all_here);
    while (m->arrived < m->expected && !m->gave_up)
        if (pthread_cond_timedwait(&m->all_here, &m->lock, &until) == ETIMEDOUT)
            m->gave_up = 1;
    pthread_mutex_unlock(&m->lock);
}

static void check_concurrent(unsigned threads)
{
    ip__pool *pool = NULL;
    REQUIRE(ip__pool_create(threads, &pool, NULL) == IP_OK);
    REQUIRE(ip__pool_threads(pool) == threads);
    for (int round = 0; round < 3; round++) {
        meeting m = {.expected = threads};
        pthread_mutex_init(&m.lock, NULL);
        pthread_cond_init(&m.all_here, NULL);
        ip__pool_run(pool, threads, meet_job, &m);
        CHECK_MSG(!m.gave_up && m.arrived == threads, "%u threads: %u jobs met", threads,
                  m.arrived);
        unsigned distinct = 0, caller = 0, blocked = 0;
        for (unsigned i = 0; i < threads; i++) {
            unsigned seen_before = 0;
            for (unsigned j = 0; j < i; j++)
                seen_before |= pthread_equal(m.who[i], m.who[j]) != 0;
            distinct += !seen_before;
            int on_caller = pthread_equal(m.who[i], pthread_self()) != 0;
            caller += on_caller;
            /* a helper never takes the process's signals; the caller's mask is its own */
            blocked += m.sigint_blocked[i] == !on_caller;
        }
        CHECK_MSG(distinct == threads && caller == 1,
                  "%u threads: %u distinct threads, the caller ran %u jobs", threads, distinct,
                  caller);
        CHECK_MSG(blocked == threads, "%u threads: %u signal masks as expected", threads, blocked);
        pthread_cond_destroy(&m.all_here);
        pthread_mutex_destroy(&m.lock);
    }
    ip__pool_destroy(pool);
}

/* The word spun on, and the mutex its writer takes (none: NULL). */
typedef struct spun {
    atomic_uint word;
    pthread_mutex_t *lock;
} spun;

/* Changes the word, under its mutex if it has one, after a pause long enough for the spinner
 * to be spinning. */
static void *change_later(void *arg)
{
    spun *s = arg;
    struct timespec pause = {0, 2000000}; /* 2 ms */
    nanosleep(&pause, NULL);
    if (s->lock)
        pthread_mutex_lock(s->lock);
    atomic_fetch_add(&s->word, 1);
    if (s->lock)
        pthread_mutex_unlock(s->lock);
    return NULL;
}

static void check_spin(void)
{
    spun s = {.lock = NULL};
    atomic_init(&s.word, 7);
    /* no time: one look */
    CHECK_EQ(ip__spin_while(&s.word, 7, 0, NULL), 0);
    CHECK_EQ(ip__spin_while(&s.word, 6, 0, NULL), 1);
    CHECK_EQ(ip__spin_while(&s.word, 6, 1e-3, NULL), 1);
    /* unchanged: it returns once its time is out, not before */
    double t0 = ip_now_seconds();
    CHECK_EQ(ip__spin_while(&s.word, 7, 1e-3, NULL), 0);
    CHECK_GE(ip_now_seconds() - t0, 1e-3);
    /* another thread's change ends the spin (long before its 30 s) */
    pthread_t other;
    REQUIRE(pthread_create(&other, NULL, change_later, &s) == 0);
    CHECK_EQ(ip__spin_while(&s.word, 7, 30.0, NULL), 1);
    CHECK_EQ(atomic_load(&s.word), 8);
    pthread_join(other, NULL);
    /* with a mutex held: let go while spinning (the writer needs it), held again after */
    pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
    s.lock = &lock;
    pthread_mutex_lock(&lock);
    REQUIRE(pthread_create(&other, NULL, change_later, &s) == 0);
    CHECK_EQ(ip__spin_while(&s.word, 8, 30.0, &lock), 1);
    CHECK_EQ(atomic_load(&s.word), 9);
    CHECK_EQ(pthread_mutex_trylock(&lock), EBUSY); /* this thread holds it */
    pthread_mutex_unlock(&lock);
    pthread_join(other, NULL);
    /* pools spin up to as many threads as cores, and not beyond */
    ip__pool *pool = NULL;
    REQUIRE(ip__pool_create(ip_thread_count(0), &pool, NULL) == IP_OK);
    CHECK_EQ(ip__pool_spin_seconds(pool), IP_SPIN_SECONDS);
    ip__pool_destroy(pool);
    if (ip_thread_count(0) < IP_MAX_THREADS) {
        REQUIRE(ip__pool_create(ip_thread_count(0) + 1, &pool, NULL) == IP_OK);
        CHECK_EQ(ip__pool_spin_seconds(pool), 0);
        ip__pool_destroy(pool);
    }
}

static void caller_job(void *user, unsigned index)
{
    pthread_t *who = user;
    who[index] = pthread_self();
}

static tally the_tally; /* (large: not on the stack) */

/* Several runs of all sizes on one pool: none, fewer jobs than threads, as many, many more. */
static void runs_of_all_sizes(void)
{
    ip__pool *pool = NULL;
    REQUIRE(ip__pool_create(4, &pool, NULL) == IP_OK);
    CHECK_EQ(ip__pool_threads(pool), 4);
    const unsigned sizes[] = {0, 1, 2, 3, 4, 5, 17, 64, 1000, MAX_JOBS};
    for (int repeat = 0; repeat < 20; repeat++)
        for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++)
            check_run(pool, &the_tally, sizes[k]);
    ip__pool_destroy(pool);
}

/* Many runs in a row, as an engine's steps: each waits for its jobs before the next. */
static void runs_in_a_row(void)
{
    ip__pool *pool = NULL;
    REQUIRE(ip__pool_create(3, &pool, NULL) == IP_OK);
    for (int repeat = 0; repeat < 2000; repeat++)
        check_run(pool, &the_tally, 1 + (unsigned)repeat % 7);
    ip__pool_destroy(pool);
}

/* A pool of 1 starts no thread: every job runs on the caller, in order. */
static void pool_of_one(void)
{
    ip__pool *pool = NULL;
    REQUIRE(ip__pool_create(1, &pool, NULL) == IP_OK);
    CHECK_EQ(ip__pool_threads(pool), 1);
    check_run(pool, &the_tally, 0);
    check_run(pool, &the_tally, 1);
    check_run(pool, &the_tally, 100);
    pthread_t who[8];
    ip__pool_run(pool, 8, caller_job, who);
    unsigned on_caller = 0;
    for (unsigned i = 0; i < 8; i++)
        on_caller += pthread_equal(who[i], pthread_self()) != 0;
    CHECK_EQ(on_caller, 8);
    ip__pool_destroy(pool);
}

/* Helpers run jobs at the same time as the caller, each job on its own thread. */
static void concurrent(void)
{
    check_concurrent(2);
    check_concurrent(4);
    check_concurrent(8);
}

/* The count is clamped to 1 .. IP_MAX_THREADS. */
static void clamped_counts(void)
{
    ip__pool *pool = NULL;
    REQUIRE(ip__pool_create(0, &pool, NULL) == IP_OK);
    CHECK_EQ(ip__pool_threads(pool), 1);
    check_run(pool, &the_tally, 10);
    ip__pool_destroy(pool);
    REQUIRE(ip__pool_create(IP_MAX_THREADS + 10, &pool, NULL) == IP_OK);
    CHECK_LE(ip__pool_threads(pool), IP_MAX_THREADS);
    check_run(pool, &the_tally, 300);
    ip__pool_destroy(pool);
}

/* Destroyed without a run, at once after its helpers started; NULL is a no-op. */
static void destroyed_unused(void)
{
    ip__pool *pool = NULL;
    for (int repeat = 0; repeat < 50; repeat++) {
        REQUIRE(ip__pool_create(1 + (unsigned)repeat % 6, &pool, NULL) == IP_OK);
        ip__pool_destroy(pool);
    }
    ip__pool_destroy(NULL);
    CHECK(1);
}

static const test_case cases[] = {
    {"runs_of_all_sizes", runs_of_all_sizes},
    {"runs_in_a_row", runs_in_a_row},
    {"pool_of_one", pool_of_one},
    {"check_concurrent", concurrent},
    {"clamped_counts", clamped_counts},
    {"destroyed_unused", destroyed_unused},
    TEST_CASE(check_spin),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_pool");
}
