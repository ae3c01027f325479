/* SPDX-License-Identifier: BSD-3-Clause */
/* isowall's watchdog: heartbeats on a helper thread, and one line naming a silent process
 * (see watch.h). */
#include <errno.h>
#include <mpi.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "watch.h"

/* The messages, one int each, on the watchdog's own communicator under one tag, so that a
 * process's last message arrives after all its heartbeats. */
enum {
    BEAT = 0, /* still here */
    BYE = 1,  /* the work is done: no more heartbeats */
    TAG = 1
};

static const int beat_message = BEAT, bye_message = BYE;

/* A process this one hears from and speaks to. */
typedef struct watch_peer {
    int rank;
    int message; /* the receive buffer */
    MPI_Request receive, beat, bye;
    double heard; /* when its last message came (seconds, monotonic) */
    int done;     /* its BYE has come */
} watch_peer;

static struct {
    const char *program;
    double timeout;  /* seconds of silence that end the wall */
    double interval; /* seconds between heartbeats */
    double poll;     /* seconds between the thread's looks */
    int rank, ranks;
    MPI_Comm comm;
    watch_peer *peers;
    int peer_count;
    int running; /* the main thread's view: a watchdog thread runs */
    pthread_t thread;
    pthread_mutex_t lock; /* guards stage and stopping */
    char stage[256];      /* what the main thread does now */
    int stopping;         /* the main thread's work is done */
} w = {.lock = PTHREAD_MUTEX_INITIALIZER};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void pause_for(double seconds)
{
    struct timespec ts = {(time_t)seconds, (long)((seconds - (double)(time_t)seconds) * 1e9)};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}

static void post_receive(watch_peer *p)
{
    MPI_Irecv(&p->message, 1, MPI_INT, p->rank, TAG, w.comm, &p->receive);
}

/* How long a peer may be silent before this process names it: process 0 names anyone at the
 * timeout; of the others, which hear only process 0, process 1 names it at the timeout and the
 * rest at twice the timeout (so that one line is printed, unless process 1 is silent too). */
static double patience(void)
{
    return w.rank <= 1 ? w.timeout : 2 * w.timeout;
}

/* Prints the one line naming the peers silent for longer than patience() at time t, and ends
 * the job. */
static void end_the_wall(double t)
{
    char names[1024] = "", stage[sizeof w.stage];
    size_t at = 0;
    int count = 0, named = 0;
    double least = -1;
    for (int i = 0; i < w.peer_count; i++)
        count += !w.peers[i].done && t - w.peers[i].heard > patience();
    for (int i = 0; i < w.peer_count; i++) {
        const watch_peer *p = &w.peers[i];
        double silence = t - p->heard;
        if (p->done || silence <= patience())
            continue;
        least = least < 0 || silence < least ? silence : least;
        const char *before = named == 0           ? (count > 1 ? "ranks " : "rank ")
                             : named == count - 1 ? " and "
                                                  : ", ";
        int n = snprintf(names + at, sizeof names - at - 16, "%s%d", before, p->rank);
        if (n < 0 || (size_t)n >= sizeof names - at - 16) { /* room for this much only */
            snprintf(names + at, sizeof names - at, " and others");
            break;
        }
        at += (size_t)n;
        named++;
    }
    pthread_mutex_lock(&w.lock);
    memcpy(stage, w.stage, sizeof stage);
    pthread_mutex_unlock(&w.lock);
    fprintf(stderr, "%s: %s sent nothing for %.1f s (rank %d was %s); ending the wall\n", w.program,
            names, least, w.rank, stage[0] ? stage : "starting");
    fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, 1);
}

static void *watch_run(void *unused)
{
    (void)unused;
    double t = now(), last_look = t, next_beat = t;
    int bye_sent = 0;
    for (;;) {
        t = now();
        /* a look long after the last one: this process itself did not run (stopped and
         * continued, or not scheduled), so the silence meanwhile is not the peers' to answer
         * for; what they sent meanwhile is read first */
        int own_gap = t - last_look > w.timeout / 2;
        last_look = t;
        for (int i = 0; i < w.peer_count; i++) {
            watch_peer *p = &w.peers[i];
            int flag = 1;
            while (!p->done && flag) {
                MPI_Test(&p->receive, &flag, MPI_STATUS_IGNORE);
                if (flag) {
                    p->heard = t;
                    if (p->message == BYE)
                        p->done = 1;
                    else
                        post_receive(p);
                }
            }
            if (own_gap)
                p->heard = t;
            /* a heartbeat whose send is done makes room for the next */
            MPI_Test(&p->beat, &flag, MPI_STATUS_IGNORE);
            MPI_Test(&p->bye, &flag, MPI_STATUS_IGNORE);
        }
        pthread_mutex_lock(&w.lock);
        int stopping = w.stopping;
        pthread_mutex_unlock(&w.lock);
        if (stopping && !bye_sent) {
            for (int i = 0; i < w.peer_count; i++)
                MPI_Isend(&bye_message, 1, MPI_INT, w.peers[i].rank, TAG, w.comm, &w.peers[i].bye);
            bye_sent = 1;
        } else if (!bye_sent && t >= next_beat) {
            for (int i = 0; i < w.peer_count; i++)
                if (w.peers[i].beat == MPI_REQUEST_NULL) /* else the last one is still going */
                    MPI_Isend(&beat_message, 1, MPI_INT, w.peers[i].rank, TAG, w.comm,
                              &w.peers[i].beat);
            next_beat = t + w.interval;
        }
        int all_done = bye_sent;
        for (int i = 0; i < w.peer_count; i++) {
            const watch_peer *p = &w.peers[i];
            if (!p->done && t - p->heard > patience())
                end_the_wall(t);
            all_done =
                all_done && p->done && p->beat == MPI_REQUEST_NULL && p->bye == MPI_REQUEST_NULL;
        }
        if (all_done)
            return NULL;
        pause_for(w.poll);
    }
}

/* A failure to start the watchdog: the line, and the end of the job (a process without its
 * thread would look silent to the others). */
static void cannot_watch(const char *what)
{
    fprintf(stderr,
            "%s: rank %d: %s for the watchdog; ending the wall (--timeout 0 runs without "
            "one)\n",
            w.program, w.rank, what);
    fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, 1);
}

void wall_watch_start(const char *program, double timeout)
{
    MPI_Comm_rank(MPI_COMM_WORLD, &w.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &w.ranks);
    if (w.ranks < 2)
        return;
    MPI_Comm_dup(MPI_COMM_WORLD, &w.comm);
    w.program = program;
    w.timeout = timeout;
    w.interval = timeout / 4 < 1.0 ? timeout / 4 : 1.0;
    w.poll = w.interval / 4 < 0.05 ? w.interval / 4 : 0.05;
    w.poll = w.poll > 0.001 ? w.poll : 0.001;
    w.peer_count = w.rank == 0 ? w.ranks - 1 : 1;
    w.peers = calloc((size_t)w.peer_count, sizeof *w.peers);
    if (!w.peers)
        cannot_watch("out of memory");
    double t = now();
    for (int i = 0; i < w.peer_count; i++) {
        watch_peer *p = &w.peers[i];
        p->rank = w.rank == 0 ? i + 1 : 0;
        p->heard = t;
        p->beat = p->bye = MPI_REQUEST_NULL;
        post_receive(p);
    }
    int rc = pthread_create(&w.thread, NULL, watch_run, NULL);
    if (rc != 0)
        cannot_watch(strerror(rc));
    w.running = 1;
}

void wall_watch_stage(const char *format, ...)
{
    if (!w.running)
        return;
    va_list args;
    va_start(args, format);
    pthread_mutex_lock(&w.lock);
    vsnprintf(w.stage, sizeof w.stage, format, args);
    pthread_mutex_unlock(&w.lock);
    va_end(args);
}

void wall_watch_stop(void)
{
    if (!w.running)
        return;
    wall_watch_stage("done, waiting for the others to finish");
    pthread_mutex_lock(&w.lock);
    w.stopping = 1;
    pthread_mutex_unlock(&w.lock);
    pthread_join(w.thread, NULL);
    w.running = 0;
    free(w.peers);
    w.peers = NULL;
    MPI_Comm_free(&w.comm);
}
