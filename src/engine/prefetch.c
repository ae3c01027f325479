/* SPDX-License-Identifier: BSD-3-Clause */
/* The engine's background reader (prefetch.h): plans from the summaries and the ray order,
 * asks the kernel for the payloads ahead, loads bricks into the cache ahead of the workers. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <time.h>

#include "cache_prefetch.h"
#include "format.h"
#include "internal.h"
#include "pool.h"
#include "prefetch.h"
#include "sampler.h"
#include "seed.h"

#define PLAN_BATCH 32                                         /* rays planned at once */
#define QUEUE_SIZE (PLAN_BATCH * IP__PREFETCH_RAY_BRICKS * 7) /* their bricks and neighbours */
#define WAIT_NS 1000000L /* how long the reader sleeps when it is far enough ahead */
#define IDLE_BATCHES 4   /* batches in a row that load nothing: the view's bricks are in */

struct ip__prefetcher {
    ip_cache *cache;
    const ip_store *store;
    const ip_layout *layout;
    uint64_t window;     /* payload bytes asked of the kernel ahead of the brick being loaded */
    int leave_in_memory; /* bricks whose payload the page cache holds are left to the workers */
    pthread_t thread;
    int started;
    pthread_mutex_t lock;
    pthread_cond_t wake; /* the reader: resume, pause or quit */
    pthread_cond_t idle; /* pause: the reader has stopped working */
    int run, busy, quit; /* under lock */
    atomic_int pause;    /* asked to stop at the next brick */
    /* The view and the plan: the reader's own between resume and pause. */
    ip__prefetch_view view;
    double lod[IP_MAX_LEVELS + 1];
    double widen[IP_MAX_LEVELS];
    ip_ray_order order; /* where the plan has got to */
    uint32_t plan_last_level;
    int plan_done, finished;
    int batch_open, batch_loaded; /* a batch is queued; a load of it read a brick */
    unsigned idle_batches;        /* batches in a row that read none */
    uint64_t below;               /* ticks before the view began: evictable for a load ahead */
    unsigned char *planned;       /* one flag per brick */
    uint64_t queue[QUEUE_SIZE];
    unsigned head, count, hinted; /* loaded up to head, asked of the kernel up to hinted */
    uint64_t hinted_bytes;        /* payload bytes of queue[head .. hinted) */
};

/* read_ahead_kb of the block device holding `path` (of the disk, for a partition), in bytes,
 * within [128 KiB, 64 MiB]; IP__PREFETCH_DEFAULT_WINDOW where it cannot be found (a file
 * system without a block device, no sysfs). */
static uint64_t device_window(const char *path)
{
    static const char *const forms[2] = {"/sys/dev/block/%u:%u/queue/read_ahead_kb",
                                         "/sys/dev/block/%u:%u/../queue/read_ahead_kb"};
    struct stat st;
    if (stat(path, &st) != 0)
        return IP__PREFETCH_DEFAULT_WINDOW;
    for (int i = 0; i < 2; i++) {
        char name[96];
        unsigned long long kb = 0;
        snprintf(name, sizeof name, forms[i], major(st.st_dev), minor(st.st_dev));
        FILE *f = fopen(name, "r");
        if (!f)
            continue;
        int got = fscanf(f, "%llu", &kb);
        fclose(f);
        if (got == 1 && kb > 0) {
            uint64_t bytes = (uint64_t)kb * 1024u;
            return bytes < (128u << 10) ? 128u << 10 : bytes > (64u << 20) ? 64u << 20 : bytes;
        }
    }
    return IP__PREFETCH_DEFAULT_WINDOW;
}

static void enqueue(ip__prefetcher *p, uint64_t g)
{
    if (!p->planned[g] && p->count < QUEUE_SIZE) {
        p->planned[g] = 1;
        p->queue[p->count++] = g;
    }
}

/* Queues the face neighbours of brick g whose range holds the isovalue. */
static void enqueue_neighbours(ip__prefetcher *p, uint64_t g)
{
    uint64_t neighbours[6];
    unsigned count = ip__brick_face_neighbours(p->layout, g, neighbours);
    for (unsigned i = 0; i < count; i++) {
        float range[2];
        ip_store_brick_range(p->store, neighbours[i], range);
        if (ip__range_active(range[0], range[1], p->view.iso) &&
            ip__clip_keeps_brick(&p->view.clip, p->layout, neighbours[i]))
            enqueue(p, neighbours[i]);
    }
}

/* The bricks the ray of pixel (x, y) would seed in, over the view's distance bands. */
static unsigned ray_bricks(ip__prefetcher *p, uint32_t x, uint32_t y, uint64_t *out)
{
    const ip__prefetch_view *v = &p->view;
    double dir[3];
    unsigned n = 0;
    ip_camera_pixel_ray(&v->basis, &v->camera, (double)x + v->region_x + 0.5,
                        (double)y + v->region_y + 0.5, dir);
    for (uint32_t k = 0; k < v->levels_used && n < IP__PREFETCH_RAY_BRICKS; k++) {
        /* the band widened as the rays walk it (cast.c): a cell of the band may reach past it */
        n += ip__seed_ray_bricks(p->store, k, v->iso, &v->clip, v->camera.eye, dir,
                                 p->lod[k] - p->widen[k], p->lod[k + 1] + p->widen[k], out + n,
                                 IP__PREFETCH_RAY_BRICKS - n);
    }
    return n;
}

/* Plans the next batch of rays into the (empty) queue: the rays' bricks in ray order, then
 * their neighbours. Returns 1 when it planned rays, 0 when it is as far ahead of the workers
 * as it may go, -1 when the plan is done. */
static int plan(ip__prefetcher *p)
{
    /* Planning walks the summaries for every ray (a third thread beside the workers): it
     * stops for the view once IDLE_BATCHES batches in a row found every brick resident, as a
     * warm cache does from the start. The workers still load whatever they miss. */
    if (p->batch_open) {
        p->idle_batches = p->batch_loaded ? 0 : p->idle_batches + 1;
        p->batch_open = p->batch_loaded = 0;
        if (p->idle_batches >= IDLE_BATCHES)
            p->plan_done = 1;
    }
    uint64_t claimed = atomic_load(p->view.claimed);
    uint64_t at = ip__ray_order_position(&p->order);
    if (at < claimed) { /* the workers have these rays: their bricks are theirs to load */
        ip__ray_order_seek(&p->order, claimed);
        at = claimed;
    }
    if (p->plan_done || at >= p->view.order_cells)
        return -1;
    uint64_t end = claimed + IP__PREFETCH_AHEAD;
    end = end < p->view.order_cells ? end : p->view.order_cells;
    uint64_t found[PLAN_BATCH * IP__PREFETCH_RAY_BRICKS];
    unsigned rays = 0, n = 0;
    uint32_t x, y;
    p->head = p->count = p->hinted = 0;
    p->hinted_bytes = 0;
    while (rays < PLAN_BATCH && ip__ray_order_next_before(&p->order, end, &x, &y)) {
        if (ip__ray_order_level(&p->order) > p->plan_last_level) {
            p->plan_done = 1; /* finer rays cross the bricks of the coarser ones */
            break;
        }
        n += ray_bricks(p, x, y, found + n);
        rays++;
    }
    for (unsigned i = 0; i < n; i++)
        enqueue(p, found[i]);
    for (unsigned i = 0; i < n; i++)
        enqueue_neighbours(p, found[i]);
    p->batch_open = rays > 0;
    return rays > 0 ? 1 : p->plan_done ? -1 : 0;
}

/* Asks the kernel for the payloads of the queued bricks up to the window ahead. */
static void hint(ip__prefetcher *p)
{
    while (p->hinted < p->count && p->hinted_bytes < p->window) {
        ip_brick_entry be;
        uint64_t g = p->queue[p->hinted++];
        ip_store_brick_entry(p->store, g, &be);
        if (be.stored_size > 0)
            ip_store_prefetch_brick(p->store, g);
        p->hinted_bytes += be.stored_size;
    }
}

/* Sleeps until the workers may have moved on, or a pause. */
static void wait_for_workers(ip__prefetcher *p)
{
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_nsec += WAIT_NS;
    if (until.tv_nsec >= 1000000000L) {
        until.tv_sec++;
        until.tv_nsec -= 1000000000L;
    }
    pthread_mutex_lock(&p->lock);
    if (!atomic_load(&p->pause))
        pthread_cond_timedwait(&p->wake, &p->lock, &until);
    pthread_mutex_unlock(&p->lock);
}

/* Loads the next queued brick ahead. */
static void load_next(ip__prefetcher *p)
{
    hint(p);
    uint64_t g = p->queue[p->head++];
    ip_brick_entry be;
    ip_store_brick_entry(p->store, g, &be);
    p->hinted_bytes -= be.stored_size; /* hint() has passed it: hinted > head */
    if (p->leave_in_memory && !p->view.load_all && ip_store_brick_in_memory(p->store, g) == 1)
        return; /* no disk to wait for: a worker that needs it loads it as fast */
    ip__prefetch_outcome got = ip__cache_prefetch_brick(p->cache, g, p->below);
    if (got == IP__PREFETCH_FULL)
        p->finished = 1; /* the budget holds this view's bricks: stop until the next view */
    p->batch_loaded |= got == IP__PREFETCH_LOADED;
}

/* The reader's work on the current view, until it is done or asked to stop. */
static void work(ip__prefetcher *p)
{
    while (!p->finished && !atomic_load(&p->pause) && !atomic_load(p->view.cancel)) {
        if (p->head < p->count) {
            load_next(p);
            continue;
        }
        int planned = plan(p);
        if (planned < 0)
            p->finished = 1;
        else if (planned == 0)
            wait_for_workers(p);
    }
}

static void *reader(void *arg)
{
    ip__prefetcher *p = arg;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (!p->quit && !p->run)
            pthread_cond_wait(&p->wake, &p->lock);
        if (p->quit)
            break;
        p->busy = 1;
        pthread_mutex_unlock(&p->lock);
        work(p);
        pthread_mutex_lock(&p->lock);
        p->busy = 0;
        p->run = 0;
        pthread_cond_broadcast(&p->idle);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

ip_status ip__prefetcher_create(ip_cache *cache, int leave_in_memory, ip__prefetcher **out)
{
    ip__prefetcher *p = calloc(1, sizeof *p);
    if (!p)
        return IP_ERR_NOMEM;
    p->leave_in_memory = leave_in_memory;
    p->cache = cache;
    p->store = ip_cache_store(cache);
    p->layout = ip_store_layout(p->store);
    p->window = device_window(ip_store_path(p->store));
    p->planned = calloc(p->layout->brick_count, 1);
    p->finished = 1; /* until a view */
    atomic_init(&p->pause, 0);
    if (!p->planned) {
        free(p);
        return IP_ERR_NOMEM;
    }
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->wake, NULL);
    pthread_cond_init(&p->idle, NULL);
    p->started = ip__thread_start(&p->thread, reader, p) == 0;
    if (!p->started) {
        ip__prefetcher_destroy(p);
        return IP_ERR_NOMEM;
    }
    *out = p;
    return IP_OK;
}

void ip__prefetcher_pause(ip__prefetcher *p)
{
    pthread_mutex_lock(&p->lock);
    atomic_store(&p->pause, 1);
    p->run = 0;
    pthread_cond_broadcast(&p->wake);
    while (p->busy)
        pthread_cond_wait(&p->idle, &p->lock);
    pthread_mutex_unlock(&p->lock);
    p->finished = 1; /* the view may change now: nothing more until ip__prefetcher_begin() */
}

void ip__prefetcher_destroy(ip__prefetcher *p)
{
    if (!p)
        return;
    if (p->started) {
        ip__prefetcher_pause(p);
        pthread_mutex_lock(&p->lock);
        p->quit = 1;
        pthread_cond_broadcast(&p->wake);
        pthread_mutex_unlock(&p->lock);
        pthread_join(p->thread, NULL);
    }
    pthread_cond_destroy(&p->idle);
    pthread_cond_destroy(&p->wake);
    pthread_mutex_destroy(&p->lock);
    free(p->planned);
    free(p);
}

void ip__prefetcher_begin(ip__prefetcher *p, const ip__prefetch_view *view)
{
    p->view = *view;
    memcpy(p->lod, view->lod_distance, (view->levels_used + 1) * sizeof *p->lod);
    memcpy(p->widen, view->band_widening, view->levels_used * sizeof *p->widen);
    p->view.lod_distance = p->lod;
    p->view.band_widening = p->widen;
    p->order = view->order;
    uint32_t last = ip__ray_order_last_level(&p->order);
    p->plan_last_level =
        last >= 2 * IP__PREFETCH_SKIP_LEVELS ? last - IP__PREFETCH_SKIP_LEVELS : last;
    memset(p->planned, 0, p->layout->brick_count);
    p->head = p->count = p->hinted = 0;
    p->hinted_bytes = 0;
    p->plan_done = 0;
    p->finished = 0;
    p->batch_open = p->batch_loaded = 0;
    p->idle_batches = 0;
    p->below = ip__cache_tick_now(p->cache);
}

void ip__prefetcher_resume(ip__prefetcher *p)
{
    pthread_mutex_lock(&p->lock);
    atomic_store(&p->pause, 0);
    p->run = 1;
    pthread_cond_signal(&p->wake);
    pthread_mutex_unlock(&p->lock);
}
