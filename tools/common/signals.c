/* SPDX-License-Identifier: BSD-3-Clause */
/* Ctrl-C and SIGTERM: recorded, the engine cancelled, and raised again at the end. */
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#include "isoprop/engine.h"
#include "tool_common.h"

static volatile sig_atomic_t signal_caught;
static _Atomic(ip_engine *) signal_engine;
static atomic_int signal_handlers_running;

static void on_signal(int sig)
{
    int saved = errno;
    atomic_fetch_add(&signal_handlers_running, 1);
    if (!signal_caught)
        signal_caught = sig;
    ip_engine *engine = atomic_load(&signal_engine);
    if (engine)
        ip_engine_cancel(engine); /* an atomic store: async-signal-safe */
    atomic_fetch_sub(&signal_handlers_running, 1);
    errno = saved;
}

void tool_signals_catch(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

int tool_signal_caught(void)
{
    return signal_caught;
}

void tool_signals_cancel_engine(ip_engine *engine)
{
    atomic_store(&signal_engine, engine);
    /* a handler running on another thread may have read the old engine: wait it out */
    while (atomic_load(&signal_handlers_running) != 0)
        sched_yield();
}

void tool_signals_forget(void)
{
    signal_caught = 0;
}

void tool_signals_reraise(void)
{
    int sig = signal_caught;
    if (!sig)
        return;
    tool_signals_cancel_engine(NULL);
    fflush(stdout);
    fflush(stderr);
    signal(sig, SIG_DFL);
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, sig);
    pthread_sigmask(SIG_UNBLOCK, &set, NULL);
    raise(sig);
}
