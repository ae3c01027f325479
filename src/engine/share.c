/* SPDX-License-Identifier: BSD-3-Clause */
/* Idle workers help the others' propagations: parts of long queues handed out during a step. */
#include <string.h>
#include "engine_state.h"
#include "internal.h"
#include "pool.h"

int ip__engine_give_cells(void *user, uint32_t level, const ip_queued_cell *cells, unsigned count,
                          const double dir[3])
{
    ip_engine *e = user;
    IP_ASSERT(count <= IP_SHARE_CELLS);
    pthread_mutex_lock(&e->share_lock);
    int room = e->shared_count < SHARED_MAX;
    if (room) {
        ip_shared_cells *c = &e->shared[e->shared_count++];
        c->level = level;
        c->count = count;
        memcpy(c->dir, dir, sizeof c->dir);
        memcpy(c->cells, cells, count * sizeof *cells);
        atomic_fetch_add(&e->share_news, 1);
        pthread_cond_signal(&e->share_wake);
    }
    pthread_mutex_unlock(&e->share_lock);
    return room;
}

void ip__engine_help(ip_engine *e, ip_engine_worker *w)
{
    pthread_mutex_lock(&e->share_lock);
    e->working--;
    while (w->status == IP_OK) {
        if (e->shared_count > 0) {
            ip_shared_cells c = e->shared[--e->shared_count];
            e->working++;
            pthread_mutex_unlock(&e->share_lock);
            w->status = ip__propagate_queued(&w->level[c.level].propagator, c.cells, c.count, c.dir,
                                             &w->counts);
            if (w->status != IP_OK)
                w->failed_level = c.level;
            pthread_mutex_lock(&e->share_lock);
            e->working--;
            continue;
        }
        if (e->working == 0)
            break;
        atomic_fetch_add(&e->hungry, 1);
        /* a short spin before sleeping: cells offered or the last worker done, soon after */
        unsigned seen = atomic_load(&e->share_news);
        int news =
            ip__spin_while(&e->share_news, seen, ip__pool_spin_seconds(e->pool), &e->share_lock);
        if (!news && e->shared_count == 0 && e->working > 0)
            pthread_cond_wait(&e->share_wake, &e->share_lock);
        atomic_fetch_sub(&e->hungry, 1);
    }
    atomic_fetch_add(&e->share_news, 1);
    pthread_cond_broadcast(&e->share_wake); /* the others may wait for working to reach 0 */
    pthread_mutex_unlock(&e->share_lock);
}
