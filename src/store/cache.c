/* SPDX-License-Identifier: BSD-3-Clause */
/* The brick cache: lock-free hits, one decode per miss, exact LRU under a byte budget. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "array.h"
#include "cache_prefetch.h"
#include "format.h"
#include "internal.h"
#include "lru_heap.h"
#include "isoprop/cache.h"

#define STRIPES 64 /* load coordination locks, by brick index */

struct entry;

/* A decoded brick. Entries are type-stable: once allocated they are recycled, never freed
 * before the cache, so a thread that read a slot's pointer may always look at the entry and
 * find out (pins < 0, or another brick) that it lost a race. */
typedef struct entry {
    atomic_int pins;           /* >= 0: pins; -1: free or being evicted */
    atomic_uint_fast64_t tick; /* last pin time, for LRU */
    atomic_uint_fast64_t brick;
    atomic_int prefetched; /* 1: loaded ahead and not pinned since */
    void *samples;         /* the samples, then (at group_offset) the cell-group ranges */
    size_t bytes;          /* of both */
    size_t capacity;       /* of samples */
    size_t group_offset;
    uint32_t extent[3], origin[3], level;
    struct entry *next_free;
    uint32_t resident_slot; /* position in the resident array */
} entry;

typedef struct slot {
    _Atomic(entry *) entry;
} slot;

/* The LRU order: a min-heap (lru_heap.h) of (tick, entry), updated lazily. A hit only stamps
 * the entry's tick (no lock); eviction pops the smallest key, and an entry whose tick moved on
 * since its key was taken is pushed back under its new tick. A popped entry whose key equals
 * its tick is the least recently used: every other key is at most its entry's tick. */

#define HIT_STRIPES 16
typedef struct padded_counter {
    _Alignas(64) atomic_uint_fast64_t value;
} padded_counter;

struct ip_cache {
    const ip_store *store;
    const ip_layout *layout;
    uint64_t budget;
    slot *slots;            /* one per brick of every level */
    atomic_uchar *touched;  /* one flag per brick */
    unsigned char *loading; /* one flag per brick, under its stripe lock */
    pthread_mutex_t stripe_lock[STRIPES];
    pthread_cond_t stripe_done[STRIPES];
    pthread_mutex_t evict_lock; /* resident set, free list, accounting */
    entry **resident;           /* resident entries, unordered */
    uint64_t resident_count, resident_capacity;
    ip_lru_heap heap; /* every resident entry once, keyed by a tick <= its last pin;
                                  its parking room holds the pinned ones evict_one() sets aside */
    entry *free_entries;
    void **spare_work; /* decode scratch buffers not in use, under evict_lock */
    uint64_t spare_count, spare_capacity;
    entry **all_entries; /* every entry ever made, for destroy */
    uint64_t all_count, all_capacity;
    size_t work_size;
    atomic_uint_fast64_t clock;
    padded_counter hits[HIT_STRIPES]; /* striped by brick: hits on different bricks do not
                                         contend for one cache line */
    atomic_uint_fast64_t misses, evictions, waits, bytes_decompressed, bytes_read, decode_ns,
        over_budget_pins, errors, touched_count;
    atomic_uint_fast64_t prefetched, prefetch_hits, wait_ns;
    atomic_uint_fast64_t prefetch_unused; /* prefetched bricks resident and not pinned yet */
    uint64_t disk_bytes_at_create;        /* ip__process_read_bytes() then */
    atomic_uint_fast64_t level_touched[32], level_misses[32];
    uint64_t resident_bytes, resident_peak; /* under evict_lock */
};

uint64_t ip_cache_default_budget(void)
{
    uint64_t budget = 512ull << 20;
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0 && (uint64_t)pages * (uint64_t)page / 4 < budget)
        budget = (uint64_t)pages * (uint64_t)page / 4;
    return budget;
}

/* Bytes of scratch fill_group_ranges() needs for a brick of extent[0] x extent[1] samples in
 * x and y (two slices and two rows). */
static size_t group_scratch_bytes(size_t row, size_t slice, ip_type type)
{
    return 2 * (slice + row) * ip_type_size(type);
}

ip_status ip_cache_create(const ip_store *store, uint64_t budget_bytes, ip_cache **out,
                          ip_error *err)
{
    if (budget_bytes == 0)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: the cache budget must be positive",
                        ip_store_path(store));
    ip_cache *c = calloc(1, sizeof *c);
    if (!c)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for a cache", ip_store_path(store));
    c->store = store;
    c->layout = ip_store_layout(store);
    c->budget = budget_bytes;
    uint64_t n = c->layout->brick_count;
    c->slots = calloc(n, sizeof *c->slots);
    c->touched = calloc(n, sizeof *c->touched);
    c->loading = calloc(n, 1);
    /* decode scratch, reused for the cell-group ranges once a brick is decoded: one allocation
     * per decoding thread, none per brick */
    size_t edge = (size_t)c->layout->brick_edge + 1,
           ranges = group_scratch_bytes(edge, edge * edge, c->layout->type);
    c->work_size = ip_store_read_work_size(store);
    c->work_size = c->work_size > ranges ? c->work_size : ranges;
    if (!c->slots || !c->touched || !c->loading) {
        ip_cache_destroy(c);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for a cache of %llu bricks",
                        ip_store_path(store), (unsigned long long)n);
    }
    for (int i = 0; i < STRIPES; i++) {
        pthread_mutex_init(&c->stripe_lock[i], NULL);
        pthread_cond_init(&c->stripe_done[i], NULL);
    }
    pthread_mutex_init(&c->evict_lock, NULL);
    c->disk_bytes_at_create = ip__process_read_bytes();
    *out = c;
    return IP_OK;
}

#ifdef NDEBUG
#define check_resident(c, at_rest) ((void)0)
#else
/* The resident set's invariants (IP_ASSERT), at the places that look at every resident entry
 * anyway; evict_lock held, or no other thread (`at_rest`: no load in flight, nothing pinned,
 * every entry resident or free). Each resident entry is where its resident_slot says, pinnable
 * (pins >= 0) and in its brick's slot; the heap holds the resident entries, each once, in heap
 * order, with none parked; the resident bytes are theirs, plus those of the loads in flight. */
static void check_resident(const ip_cache *c, int at_rest)
{
    uint64_t bytes = 0;
    for (uint64_t i = 0; i < c->resident_count; i++) {
        const entry *e = c->resident[i];
        uint64_t g = atomic_load(&e->brick);
        IP_ASSERT(e->resident_slot == i);
        IP_ASSERT(atomic_load(&e->pins) >= 0);
        IP_ASSERT(!at_rest || atomic_load(&e->pins) == 0); /* ip_cache_destroy(): none pinned */
        IP_ASSERT(g < c->layout->brick_count && atomic_load(&c->slots[g].entry) == e);
        bytes += e->bytes;
    }
    IP_ASSERT(at_rest ? bytes == c->resident_bytes : bytes <= c->resident_bytes);
    IP_ASSERT(c->resident_peak >= c->resident_bytes);
    IP_ASSERT(c->heap.count == c->resident_count && c->heap.parked_count == 0);
    for (uint64_t i = 0; i < c->heap.count; i++) { /* each resident entry, so each once */
        const entry *e = c->heap.items[i].value;
        IP_ASSERT(e->resident_slot < c->resident_count && c->resident[e->resident_slot] == e);
        IP_ASSERT(i == 0 || c->heap.items[(i - 1) / 2].key <= c->heap.items[i].key);
    }
    if (at_rest) { /* the other entries are free */
        uint64_t free_count = 0;
        for (const entry *e = c->free_entries; e; e = e->next_free, free_count++)
            IP_ASSERT(atomic_load(&e->pins) == -1);
        IP_ASSERT(c->resident_count + free_count == c->all_count);
    }
}
#endif

void ip_cache_destroy(ip_cache *c)
{
    if (!c)
        return;
    check_resident(c, 1);
    for (uint64_t i = 0; i < c->all_count; i++) {
        free(c->all_entries[i]->samples);
        free(c->all_entries[i]);
    }
    if (c->slots) {
        for (int i = 0; i < STRIPES; i++) {
            pthread_mutex_destroy(&c->stripe_lock[i]);
            pthread_cond_destroy(&c->stripe_done[i]);
        }
        pthread_mutex_destroy(&c->evict_lock);
    }
    for (uint64_t i = 0; i < c->spare_count; i++)
        free(c->spare_work[i]);
    free(c->spare_work);
    free(c->all_entries);
    free(c->resident);
    ip__lru_heap_free(&c->heap);
    free(c->slots);
    free((void *)c->touched);
    free(c->loading);
    free(c);
}

const ip_store *ip_cache_store(const ip_cache *c)
{
    return c->store;
}

static void fill_brick(const entry *e, ip_brick *b)
{
    b->samples = e->samples;
    b->group_ranges = (const char *)e->samples + e->group_offset;
    memcpy(b->extent, e->extent, sizeof b->extent);
    memcpy(b->origin, e->origin, sizeof b->origin);
    b->level = e->level;
    b->index = atomic_load_explicit(&e->brick, memory_order_relaxed);
}

/* Bits of a brick's `touched` byte: pinned at least once; its payload asked for in advance. */
enum {
    TOUCHED = 1,
    PREFETCHED = 2
};

static void note_touch(ip_cache *c, uint64_t g, uint32_t level)
{
    if (!(atomic_load_explicit(&c->touched[g], memory_order_relaxed) & TOUCHED) &&
        !(atomic_fetch_or(&c->touched[g], TOUCHED) & TOUCHED)) {
        atomic_fetch_add(&c->touched_count, 1);
        atomic_fetch_add(&c->level_touched[level], 1);
    }
}

/* The hit path: pin the slot's entry if it holds brick g, counted as a hit. No lock. */
static int try_pin(ip_cache *c, uint64_t g, ip_brick *b)
{
    entry *e = atomic_load_explicit(&c->slots[g].entry, memory_order_acquire);
    if (!e)
        return 0;
    int p = atomic_load(&e->pins);
    do {
        if (p < 0)
            return 0; /* being evicted */
    } while (!atomic_compare_exchange_weak(&e->pins, &p, p + 1));
    /* pinned: it cannot be evicted now, but it may have been recycled for another brick
     * between our load of the slot and the pin */
    if (atomic_load(&e->brick) != g || atomic_load(&c->slots[g].entry) != e) {
        /* undo */
        atomic_fetch_sub(&e->pins, 1);
        return 0;
    }
    atomic_store_explicit(&e->tick, atomic_fetch_add(&c->clock, 1) + 1, memory_order_relaxed);
    if (atomic_load_explicit(&e->prefetched, memory_order_relaxed) &&
        atomic_exchange(&e->prefetched, 0)) { /* the first pin of a brick loaded ahead */
        atomic_fetch_add(&c->prefetch_hits, 1);
        atomic_fetch_sub(&c->prefetch_unused, 1);
    }
    fill_brick(e, b);
    atomic_fetch_add_explicit(&c->hits[g % HIT_STRIPES].value, 1, memory_order_relaxed);
    return 1;
}

/* Adds `e` under its current tick. evict_lock held; the room was made by
 * ip__lru_heap_reserve(). */
static void heap_push(ip_cache *c, entry *e)
{
    ip__lru_heap_push(&c->heap, atomic_load_explicit(&e->tick, memory_order_relaxed), e);
}

/* Removes the least recently pinned unpinned entry from the resident set and returns it (still
 * holding its samples buffer), or NULL when every resident entry is pinned or when that entry
 * was pinned (or loaded) at tick `below` or later. O(log n) per call, amortised over the hits
 * since. evict_lock held. */
static entry *evict_one(ip_cache *c, uint64_t below)
{
    entry *victim = NULL;
    while (c->heap.count > 0) {
        ip_lru_item top = ip__lru_heap_pop(&c->heap);
        entry *e = top.value;
        uint64_t tick = atomic_load_explicit(&e->tick, memory_order_relaxed);
        if (tick != top.key) { /* pinned since its key was taken: re-key it */
            ip__lru_heap_push(&c->heap, tick, e);
            continue;
        }
        if (tick >= below) { /* too recent: every other unpinned entry is more recent still */
            ip__lru_heap_push(&c->heap, tick, e);
            break;
        }
        int zero = 0;
        if (atomic_compare_exchange_strong(&e->pins, &zero, -1)) {
            victim = e;
            break;
        }
        ip__lru_heap_park(&c->heap, top); /* pinned now: set aside, given back below */
    }
    ip__lru_heap_unpark(&c->heap);
    if (!victim)
        return NULL;
    if (atomic_exchange(&victim->prefetched, 0)) /* loaded ahead for nothing */
        atomic_fetch_sub(&c->prefetch_unused, 1);
    IP_ASSERT(victim->resident_slot < c->resident_count &&
              c->resident[victim->resident_slot] == victim);
    IP_ASSERT(atomic_load(&c->slots[atomic_load(&victim->brick)].entry) == victim);
    IP_ASSERT(c->resident_bytes >= victim->bytes);
    atomic_store(&c->slots[atomic_load(&victim->brick)].entry, NULL);
    c->resident[victim->resident_slot] = c->resident[--c->resident_count];
    c->resident[victim->resident_slot]->resident_slot = victim->resident_slot;
    c->resident_bytes -= victim->bytes;
    return victim;
}

/* Returns an entry to the free list. Its samples go back to the allocator: only the entry
 * itself must stay allocated (see struct entry), and holding buffers of every size ever seen
 * would let memory outgrow the budget when brick sizes vary. evict_lock held. */
static void free_entry(ip_cache *c, entry *e)
{
    IP_ASSERT(atomic_load(&e->pins) == -1); /* evicted, or never published */
    IP_ASSERT(atomic_load(&e->brick) == UINT64_MAX ||
              atomic_load(&c->slots[atomic_load(&e->brick)].entry) != e);
    free(e->samples);
    e->samples = NULL;
    e->capacity = 0;
    e->next_free = c->free_entries;
    c->free_entries = e;
}

static entry *new_entry(ip_cache *c)
{
    if (ip__array_reserve(&c->all_entries, &c->all_capacity, c->all_count + 1,
                          sizeof *c->all_entries, 64) != IP_OK)
        return NULL;
    entry *e = calloc(1, sizeof *e);
    if (!e)
        return NULL;
    atomic_init(&e->pins, -1);
    atomic_init(&e->brick, UINT64_MAX);
    atomic_init(&e->prefetched, 0);
    c->all_entries[c->all_count++] = e;
    return e;
}

/* Makes room for `bytes`, counts them as resident (a load in flight holds its memory too, so
 * parallel misses cannot overshoot the budget), and returns a free entry whose buffer holds
 * exactly `bytes`. The last victim's buffer is reused when it has the right size, which is
 * the common case of equal bricks. A load ahead (`ahead`, evicting only entries last pinned
 * before tick `below`) never goes over budget: it returns NULL with *full set when the room
 * is not there. evict_lock held. */
static entry *reserve_entry(ip_cache *c, size_t bytes, int ahead, uint64_t below, int *full)
{
    entry *spare = NULL;
    *full = 0;
    while (c->resident_bytes + bytes > c->budget && (c->resident_count > 0 || ahead)) {
        entry *victim = c->resident_count > 0 ? evict_one(c, ahead ? below : UINT64_MAX) : NULL;
        if (!victim && ahead) {
            if (spare)
                free_entry(c, spare);
            *full = 1;
            return NULL;
        }
        if (!victim) {
            atomic_fetch_add(&c->over_budget_pins, 1);
            break;
        }
        atomic_fetch_add(&c->evictions, 1);
        if (spare)
            free_entry(c, spare);
        spare = victim;
    }
    IP_ASSERT(!ahead || c->resident_bytes + bytes <= c->budget); /* never over budget */
    entry *e = spare;
    if (!e && c->free_entries) {
        e = c->free_entries;
        c->free_entries = e->next_free;
    }
    if (!e && !(e = new_entry(c)))
        return NULL;
    IP_ASSERT(atomic_load(&e->pins) == -1); /* not pinnable until load_brick() publishes it */
    if (e->capacity != bytes) {
        free(e->samples);
        e->samples = malloc(bytes);
        e->capacity = e->samples ? bytes : 0;
        if (!e->samples) {
            free_entry(c, e);
            return NULL;
        }
    }
    c->resident_bytes += bytes;
    if (c->resident_bytes > c->resident_peak)
        c->resident_peak = c->resident_bytes;
    return e;
}

static ip_status add_resident(ip_cache *c, entry *e)
{
    if (ip__array_reserve(&c->resident, &c->resident_capacity, c->resident_count + 1,
                          sizeof *c->resident, 64) != IP_OK)
        return IP_ERR_NOMEM;
    /* the parking room of evict_one() may hold every resident entry at once */
    if (ip__lru_heap_reserve(&c->heap, c->heap.count + 1) != IP_OK)
        return IP_ERR_NOMEM;
    IP_ASSERT(c->resident_count < UINT32_MAX); /* fits in resident_slot */
    e->resident_slot = (uint32_t)c->resident_count;
    c->resident[c->resident_count++] = e;
    heap_push(c, e);
    return IP_OK;
}

/* Asks the kernel to read, in the background, the payloads of the face neighbours of `brick`
 * that were never pinned nor asked for: propagation crosses
 * brick faces, so on a cold page cache they are the next reads, and their I/O then overlaps
 * the decoding and extraction of this one instead of stalling a worker on a read. Costs
 * a system call per neighbour, once per brick; no thread of ours waits for the reads. */
static void prefetch_neighbours(ip_cache *c, uint64_t brick)
{
    uint64_t neighbours[6];
    unsigned count = ip__brick_face_neighbours(c->layout, brick, neighbours);
    for (unsigned i = 0; i < count; i++) {
        uint64_t g = neighbours[i];
        if (atomic_load_explicit(&c->touched[g], memory_order_relaxed) ||
            atomic_fetch_or(&c->touched[g], PREFETCHED))
            continue;
        ip_store_prefetch_brick(c->store, g);
    }
}

/* Decode scratch comes from a small pool: one buffer per thread decoding at once. */
static void *take_work(ip_cache *c)
{
    void *w = NULL;
    pthread_mutex_lock(&c->evict_lock);
    if (c->spare_count > 0)
        w = c->spare_work[--c->spare_count];
    pthread_mutex_unlock(&c->evict_lock);
    return w ? w : malloc(c->work_size);
}

static void give_work(ip_cache *c, void *w)
{
    pthread_mutex_lock(&c->evict_lock);
    /* when the pool cannot grow, the buffer is freed instead */
    if (ip__array_reserve(&c->spare_work, &c->spare_capacity, c->spare_count + 1,
                          sizeof *c->spare_work, 8) == IP_OK) {
        c->spare_work[c->spare_count++] = w;
        w = NULL;
    }
    pthread_mutex_unlock(&c->evict_lock);
    free(w);
}

/* The last sample of cell group g along an axis of `extent` samples: the group's cells are
 * G g .. G g + G - 1, or fewer where the axis's cells (samples 0 .. extent - 2) end before. */
static uint32_t group_last_sample(uint32_t g, uint32_t extent)
{
    uint32_t last = IP_CELL_GROUP * (g + 1);
    return last < extent - 1 ? last : extent - 1;
}

/* The cell-group ranges of a brick (ip_brick.group_ranges) from its samples `s` of type T, in
 * one pass over the samples: each group's layers of cells along z (G + 1 sample slices) are
 * reduced to one slice of least and greatest values (`lo`, `hi`: extent[0] * extent[1]
 * samples each), each group's rows along y of that to one row (`row_lo`, `row_hi`: extent[0]
 * each), whose windows of G + 1 samples along x are the groups. The first two steps are
 * elementwise over contiguous samples, which the compiler vectorises. */
#define GROUP_RANGES_AS(T, name)                                                              \
    /* lo, hi[0 .. n) = the least of src_lo, the greatest of src_hi over the layers `first` \
     * .. `last` (inclusive), `stride` apart */ \
    static void layers_##name(T *lo, T *hi, const T *src_lo, const T *src_hi, size_t stride,  \
                              size_t n, uint32_t first, uint32_t last)                        \
    {                                                                                         \
        memcpy(lo, src_lo + first * stride, n * sizeof(T));                                   \
        memcpy(hi, src_hi + first * stride, n * sizeof(T));                                   \
        for (uint32_t l = first + 1; l <= last; l++) {                                        \
            const T *p = src_lo + l * stride, *q = src_hi + l * stride;                       \
            for (size_t i = 0; i < n; i++) {                                                  \
                lo[i] = p[i] < lo[i] ? p[i] : lo[i];                                          \
                hi[i] = q[i] > hi[i] ? q[i] : hi[i];                                          \
            }                                                                                 \
        }                                                                                     \
    }                                                                                         \
    static void name(const T *s, const uint32_t e[3], T *out, T *scratch)                     \
    {                                                                                         \
        size_t row = e[0], slice = row * e[1];                                                \
        T *lo = scratch, *hi = lo + slice, *row_lo = hi + slice, *row_hi = row_lo + row;      \
        uint32_t n[3] = {ip_cell_groups(e[0]), ip_cell_groups(e[1]), ip_cell_groups(e[2])};   \
        for (uint32_t gz = 0; gz < n[2]; gz++) {                                              \
            layers_##name(lo, hi, s, s, slice, slice, IP_CELL_GROUP *gz,                      \
                          group_last_sample(gz, e[2]));                                       \
            for (uint32_t gy = 0; gy < n[1]; gy++) {                                          \
                layers_##name(row_lo, row_hi, lo, hi, row, row, IP_CELL_GROUP *gy,            \
                              group_last_sample(gy, e[1]));                                   \
                for (uint32_t gx = 0; gx < n[0]; gx++, out += 2) {                            \
                    uint32_t x = IP_CELL_GROUP * gx, last = group_last_sample(gx, e[0]);      \
                    T least = row_lo[x], most = row_hi[x];                                    \
                    for (x++; x <= last; x++) {                                               \
                        least = row_lo[x] < least ? row_lo[x] : least;                        \
                        most = row_hi[x] > most ? row_hi[x] : most;                           \
                    }                                                                         \
                    out[0] = least;                                                           \
                    out[1] = most;                                                            \
                }                                                                             \
            }                                                                                 \
        }                                                                                     \
    }
GROUP_RANGES_AS(uint8_t, group_ranges_uint8)
GROUP_RANGES_AS(uint16_t, group_ranges_uint16)
GROUP_RANGES_AS(int16_t, group_ranges_int16)
GROUP_RANGES_AS(float, group_ranges_float32)
#undef GROUP_RANGES_AS

/* Bytes of a brick's entry: its samples, padded to 8, then its cell-group ranges. */
static size_t entry_bytes(const uint32_t extent[3], ip_type type, size_t *group_offset)
{
    size_t size = ip_type_size(type);
    size_t samples = (size_t)extent[0] * extent[1] * extent[2] * size;
    size_t groups =
        (size_t)ip_cell_groups(extent[0]) * ip_cell_groups(extent[1]) * ip_cell_groups(extent[2]);
    *group_offset = (samples + 7) & ~(size_t)7;
    return *group_offset + 2 * groups * size;
}

/* Fills the cell-group ranges of e from its samples, with `scratch` (a decode work buffer,
 * which is at least group_scratch_bytes() for the largest brick). */
static void fill_group_ranges(ip_cache *c, entry *e, void *scratch)
{
    ip_type type = c->layout->type;
    void *out = (char *)e->samples + e->group_offset;
    switch (type) {
    case IP_UINT8: group_ranges_uint8(e->samples, e->extent, out, scratch); break;
    case IP_UINT16: group_ranges_uint16(e->samples, e->extent, out, scratch); break;
    case IP_INT16: group_ranges_int16(e->samples, e->extent, out, scratch); break;
    case IP_FLOAT32: group_ranges_float32(e->samples, e->extent, out, scratch); break;
    }
}

/* Decodes brick g into e (not yet published), and computes its cell-group ranges. */
static ip_status decode_into(ip_cache *c, uint64_t g, entry *e, ip_error *err)
{
    void *work = take_work(c);
    if (!work)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for brick %llu",
                        ip_store_path(c->store), (unsigned long long)g);
    double t0 = ip_now_seconds();
    ip_status st = ip_store_read_brick(c->store, g, e->samples, work, err);
    if (st == IP_OK) /* the work buffer is free again: its scratch for the ranges */
        fill_group_ranges(c, e, work);
    give_work(c, work);
    double t1 = ip_now_seconds();
    atomic_fetch_add(&c->decode_ns, (uint64_t)((t1 - t0) * 1e9));
    ip_brick_entry be;
    ip_store_brick_entry(c->store, g, &be);
    atomic_fetch_add(&c->bytes_read, be.stored_size);
    return st;
}

/* Loads brick g, which this thread has marked as loading, and publishes it: pinned once into
 * *b (a miss), or unpinned and marked as loaded ahead (`ahead`, see ip__cache_prefetch_brick():
 * it evicts only entries last pinned before tick `below`, and when there is no such room it
 * publishes nothing, sets *full and returns IP_OK). */
static ip_status load_brick(ip_cache *c, uint64_t g, int ahead, uint64_t below, ip_brick *b,
                            int *full, ip_error *err)
{
    uint32_t level, brick[3], origin[3], extent[3];
    ip_brick_coords(c->layout, g, &level, brick);
    ip_brick_extent(c->layout, level, brick, origin, extent);
    size_t group_offset, bytes = entry_bytes(extent, c->layout->type, &group_offset);
    pthread_mutex_lock(&c->evict_lock);
    entry *e = reserve_entry(c, bytes, ahead, below, full);
    pthread_mutex_unlock(&c->evict_lock);
    if (!e)
        return *full ? IP_OK
                     : ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for brick %llu",
                                ip_store_path(c->store), (unsigned long long)g);
    /* The decoder writes every byte: one system call (outside the lock) instead of a page
     * fault per page of a fresh buffer; next to nothing for a recycled one. */
    ip__memory_populate(e->samples, bytes);
    e->bytes = bytes;
    e->group_offset = group_offset;
    e->level = level;
    memcpy(e->extent, extent, sizeof extent);
    memcpy(e->origin, origin, sizeof origin);
    if (!ahead) /* a load ahead follows its own plan */
        prefetch_neighbours(c, g);
    ip_status st = decode_into(c, g, e, err);
    pthread_mutex_lock(&c->evict_lock);
    atomic_store(&e->tick, atomic_fetch_add(&c->clock, 1) + 1);
    if (st == IP_OK)
        st = add_resident(c, e);
    if (st != IP_OK) {
        c->resident_bytes -= bytes;
        free_entry(c, e);
        pthread_mutex_unlock(&c->evict_lock);
        if (!ahead)
            atomic_fetch_add(&c->errors, 1);
        return st == IP_ERR_NOMEM ? ip__fail(err, st, "%s: out of memory for brick %llu",
                                             ip_store_path(c->store), (unsigned long long)g)
                                  : st;
    }
    atomic_store(&e->brick, g);
    atomic_store(&e->prefetched, ahead);
    if (ahead) { /* counted before the slot shows it, so that its first pin finds it counted */
        atomic_fetch_add(&c->prefetched, 1);
        atomic_fetch_add(&c->prefetch_unused, 1);
    }
    atomic_store(&e->pins, ahead ? 0 : 1);
    /* brick g was not resident (one load per brick, see claim_load()): its slot is empty */
    IP_ASSERT(atomic_load(&c->slots[g].entry) == NULL);
    atomic_store_explicit(&c->slots[g].entry, e, memory_order_release);
    pthread_mutex_unlock(&c->evict_lock);
    atomic_fetch_add(&c->bytes_decompressed,
                     (uint64_t)extent[0] * extent[1] * extent[2] * ip_type_size(c->layout->type));
    if (ahead)
        return IP_OK;
    atomic_fetch_add(&c->misses, 1);
    atomic_fetch_add(&c->level_misses[level], 1);
    fill_brick(e, b);
    return IP_OK;
}

/* Adds the time since t0 to the time callers waited for bricks. */
static void add_wait(ip_cache *c, double t0)
{
    double waited = ip_now_seconds() - t0;
    atomic_fetch_add(&c->wait_ns, waited > 0 ? (uint64_t)(waited * 1e9) : 0);
}

/* Marks brick g as loading by this thread (0), or returns 1 when it is resident or another
 * thread is loading it. Stripe lock held. */
static int claim_load(ip_cache *c, uint64_t g)
{
    if (c->loading[g])
        return 1;
    entry *e = atomic_load(&c->slots[g].entry); /* published while loading: final now */
    if (e && atomic_load(&e->brick) == g && atomic_load(&e->pins) >= 0)
        return 1;
    c->loading[g] = 1;
    return 0;
}

/* Clears brick g's loading mark and wakes the threads waiting for it. */
static void end_load(ip_cache *c, uint64_t g)
{
    pthread_mutex_t *lock = &c->stripe_lock[g % STRIPES];
    pthread_mutex_lock(lock);
    c->loading[g] = 0;
    pthread_cond_broadcast(&c->stripe_done[g % STRIPES]);
    pthread_mutex_unlock(lock);
}

ip_status ip_cache_pin_brick(ip_cache *c, uint64_t g, ip_brick *b, ip_error *err)
{
    if (g >= c->layout->brick_count)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: brick %llu does not exist",
                        ip_store_path(c->store), (unsigned long long)g);
    uint32_t level, brick[3];
    ip_brick_coords(c->layout, g, &level, brick);
    note_touch(c, g, level);
    if (try_pin(c, g, b))
        return IP_OK;
    double t0 = ip_now_seconds(); /* from here on the caller waits for the brick */
    pthread_mutex_t *lock = &c->stripe_lock[g % STRIPES];
    pthread_mutex_lock(lock);
    int waited = 0;
    for (;;) {
        if (try_pin(c, g, b)) {
            pthread_mutex_unlock(lock);
            if (waited)
                atomic_fetch_add(&c->waits, 1);
            add_wait(c, t0);
            return IP_OK;
        }
        if (!c->loading[g])
            break;
        waited = 1;
        pthread_cond_wait(&c->stripe_done[g % STRIPES], lock);
    }
    c->loading[g] = 1;
    pthread_mutex_unlock(lock);
    int full;
    ip_status st = load_brick(c, g, 0, UINT64_MAX, b, &full, err);
    end_load(c, g);
    add_wait(c, t0);
    return st;
}

int ip__cache_pin_resident(ip_cache *c, uint64_t g, ip_brick *b)
{
    return g < c->layout->brick_count && try_pin(c, g, b);
}

uint64_t ip__cache_tick_now(const ip_cache *c)
{
    return atomic_load(&((ip_cache *)c)->clock) + 1;
}

uint64_t ip__cache_prefetch_unused(const ip_cache *c)
{
    return atomic_load(&((ip_cache *)c)->prefetch_unused);
}

ip__prefetch_outcome ip__cache_prefetch_brick(ip_cache *c, uint64_t g, uint64_t below)
{
    if (g >= c->layout->brick_count)
        return IP__PREFETCH_FAILED;
    pthread_mutex_t *lock = &c->stripe_lock[g % STRIPES];
    pthread_mutex_lock(lock);
    int present = claim_load(c, g);
    pthread_mutex_unlock(lock);
    if (present)
        return IP__PREFETCH_PRESENT;
    int full = 0;
    ip_status st = load_brick(c, g, 1, below, NULL, &full, NULL);
    end_load(c, g);
    return st != IP_OK ? IP__PREFETCH_FAILED : full ? IP__PREFETCH_FULL : IP__PREFETCH_LOADED;
}

void ip_cache_unpin_brick(ip_cache *c, const ip_brick *b)
{
    entry *e = atomic_load_explicit(&c->slots[b->index].entry, memory_order_acquire);
    /* a pinned brick stays in its slot, so the slot still holds its entry */
    IP_ASSERT(e != NULL && atomic_load(&e->brick) == b->index);
    int pins = atomic_fetch_sub(&e->pins, 1);
    IP_ASSERT(pins >= 1); /* pinned by this caller: never below zero once released */
}

uint64_t ip_cache_trim(ip_cache *c, uint64_t keep_bytes)
{
    uint64_t freed = 0;
    pthread_mutex_lock(&c->evict_lock);
    while (c->resident_bytes > keep_bytes) {
        entry *victim = evict_one(c, UINT64_MAX);
        if (!victim)
            break; /* the rest is pinned */
        freed += victim->bytes;
        free_entry(c, victim);
    }
    check_resident(c, 0);
    pthread_mutex_unlock(&c->evict_lock);
    return freed;
}

void ip_cache_get_stats(const ip_cache *cc, ip_cache_stats *s)
{
    ip_cache *c = (ip_cache *)cc; /* the lock is taken for a consistent resident snapshot */
    memset(s, 0, sizeof *s);
    s->budget_bytes = c->budget;
    pthread_mutex_lock(&c->evict_lock);
    s->resident_bytes = c->resident_bytes;
    s->resident_peak_bytes = c->resident_peak;
    s->resident_bricks = c->resident_count;
    for (uint64_t i = 0; i < c->resident_count; i++) /* pinned bytes, counted when asked */
        if (atomic_load(&c->resident[i]->pins) > 0)
            s->pinned_bytes += c->resident[i]->bytes;
    check_resident(c, 0);
    pthread_mutex_unlock(&c->evict_lock);
    for (int i = 0; i < HIT_STRIPES; i++)
        s->hits += atomic_load(&c->hits[i].value);
    s->misses = atomic_load(&c->misses);
    s->evictions = atomic_load(&c->evictions);
    s->waits = atomic_load(&c->waits);
    s->bytes_decompressed = atomic_load(&c->bytes_decompressed);
    s->bytes_read = atomic_load(&c->bytes_read);
    s->decode_seconds = (double)atomic_load(&c->decode_ns) * 1e-9;
    s->over_budget_pins = atomic_load(&c->over_budget_pins);
    s->errors = atomic_load(&c->errors);
    s->prefetched = atomic_load(&c->prefetched);
    s->prefetch_hits = atomic_load(&c->prefetch_hits);
    uint64_t disk = ip__process_read_bytes();
    s->bytes_read_disk = disk > c->disk_bytes_at_create ? disk - c->disk_bytes_at_create : 0;
    s->wait_seconds = (double)atomic_load(&c->wait_ns) * 1e-9;
    s->bricks_touched = atomic_load(&c->touched_count);
    s->bricks_total = c->layout->brick_count;
    s->levels = c->layout->level_count;
    for (uint32_t k = 0; k < c->layout->level_count && k < 32; k++) {
        s->level[k].bricks_total = c->layout->levels[k].brick_count;
        s->level[k].bricks_touched = atomic_load(&c->level_touched[k]);
        s->level[k].misses = atomic_load(&c->level_misses[k]);
    }
}
