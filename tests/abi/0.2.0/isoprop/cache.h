/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: the brick cache: decoded bricks in memory, up to a byte budget, least recently
 * used evicted first.
 *
 * ip_cache_pin_brick() returns a brick's decoded samples, loading and decoding it on a miss
 * (its checksum is verified then), and pins it: a pinned brick is never evicted until its
 * caller unpins it. When the pinned bricks alone exceed the budget the cache goes over budget
 * rather than fail, and counts it (ip_cache_stats.over_budget_pins).
 *
 * Threads: every function may be called from many threads at once. A hit takes no lock (an
 * atomic pin on the brick's slot); misses on different bricks decode in parallel; two threads
 * that miss on the same brick decode it once (the second waits for the first). Eviction is
 * exact LRU over the last pin time of each unpinned brick.
 *
 * Memory: resident bytes are the decoded bricks with their cell-group ranges (ip_brick: 2
 * samples per 8 cells, 23 % more than the samples of a 33^3 brick); a miss reads its compressed
 * payload into a scratch buffer (ip_store_read_brick()), so the process holds the budget, the
 * summaries and a fixed overhead, whatever the file's size.
 *
 * Loading ahead: a background reader (the engine's, with ip_engine_options.prefetch) may load
 * bricks before their first pin, within the budget (docs/cache.md, "Prefetching"); such loads
 * count in `prefetched` and `prefetch_hits`, not in `misses`; their reads and decodes count in
 * `bytes_read`, `bytes_decompressed` and `decode_seconds` like those of misses.
 *
 * Read-ahead: a miss also asks the kernel to read the compressed payloads of the brick's six
 * face neighbours in the background (once per brick), the bricks propagation crosses into
 * next, so that a cold start does not stall on their reads.
 */
#ifndef ISOPROP_CACHE_H
#define ISOPROP_CACHE_H

#include <stdint.h>

#include "isoprop/status.h"
#include "isoprop/store.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ip_cache ip_cache;

/* Cells along each edge of a cell group (ip_brick.group_ranges). */
#define IP_CELL_GROUP 4

/*! ip_cell_groups() : the cell groups along an axis of a brick of `extent` samples
 *  (extent - 1 cells, in groups of IP_CELL_GROUP, the last one narrower where they do not
 *  divide evenly). */
static inline uint32_t ip_cell_groups(uint32_t extent)
{
    return (extent + IP_CELL_GROUP - 2) / IP_CELL_GROUP;
}

/* A pinned, decoded brick. Owned by the cache; valid until ip_cache_unpin_brick().
 *
 * group_ranges: the brick's cells in groups of G x G x G (G = IP_CELL_GROUP), ip_cell_groups(
 * extent[k]) groups along axis k, x fastest; group (i, j, k) holds the brick's cells Gi ..
 * Gi + G - 1 along x (fewer where the brick's cells end before), likewise along y and z. For
 * each group, the least and then the greatest of the samples at its cells' corners, as two
 * samples of the volume's type: computed once per decode, so that a reader can pass over the
 * cells of a group whose range the iso-value does not split (no corner >= iso, or none < iso)
 * without reading their corners. */
typedef struct ip_brick {
    const void *samples;      /* extent[0] * extent[1] * extent[2] samples, host order, x fastest */
    const void *group_ranges; /* 2 samples per cell group, as described above */
    uint32_t extent[3];       /* samples along each axis, the + face layer included */
    uint32_t origin[3];       /* level coordinates of sample (0,0,0) */
    uint32_t level;
    uint64_t index; /* global brick index */
} ip_brick;

typedef struct ip_cache_level_stats {
    uint64_t bricks_total;   /* bricks of this level in the file */
    uint64_t bricks_touched; /* distinct bricks of this level pinned at least once */
    uint64_t misses;         /* decodes of this level's bricks */
} ip_cache_level_stats;

typedef struct ip_cache_stats {
    uint64_t budget_bytes;
    uint64_t resident_bytes;      /* decoded bytes held now */
    uint64_t resident_peak_bytes; /* most decoded bytes held at once */
    uint64_t resident_bricks;
    uint64_t hits, misses, evictions; /* evictions: bricks evicted to make room */
    uint64_t waits;                   /* misses that waited for another thread's decode */
    uint64_t bytes_decompressed;      /* decoded sample bytes produced by loads */
    uint64_t bytes_read;              /* compressed payload bytes read by loads */
    double decode_seconds;            /* time in checksum + decode + cell-group ranges,
                                         summed over threads */
    uint64_t over_budget_pins;        /* loads that found every resident brick pinned */
    uint64_t pinned_bytes;            /* decoded bytes pinned now */
    uint64_t errors;                  /* loads that failed: read, checksum or decode */
    uint64_t prefetched;      /* bricks loaded ahead by a background reader (not in misses) */
    uint64_t prefetch_hits;   /* bricks loaded ahead and then pinned before their eviction */
    uint64_t bytes_read_disk; /* bytes the process read from the block device since the cache
                                 was created (Linux /proc/self/io read_bytes; 0 elsewhere) */
    double wait_seconds;      /* time pin calls waited for a brick: their own read + decode on a
                                 miss, or another thread's load in flight; summed over threads */
    uint64_t bricks_touched, bricks_total;
    uint32_t levels;
    ip_cache_level_stats level[32];
    uint64_t reserved[8]; /* zero: room for later fields at the same size (status.h) */
} ip_cache_stats;

/*! ip_cache_default_budget() : 512 MiB, or a quarter of the machine's RAM if smaller; bytes. */
IP_API uint64_t ip_cache_default_budget(void);

/*! ip_cache_create() : a cache over `store` (which must outlive it) holding up to
 *  `budget_bytes` of decoded bricks. *out is owned by the caller, released with
 *  ip_cache_destroy(). @return IP_OK, IP_ERR_ARGUMENT (budget 0) or IP_ERR_NOMEM. */
IP_API ip_status ip_cache_create(const ip_store *store, uint64_t budget_bytes, ip_cache **out,
                                 ip_error *err);

/*! ip_cache_destroy() : frees every brick; no brick may still be pinned. NULL is allowed. */
IP_API void ip_cache_destroy(ip_cache *cache);

/*! ip_cache_get_stats() : a snapshot of the counters (consistent per counter, not across them
 *  while other threads work). */
IP_API void ip_cache_get_stats(const ip_cache *cache, ip_cache_stats *stats);

/*! ip_cache_store() : the store the cache reads from. */
IP_API const ip_store *ip_cache_store(const ip_cache *cache);

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same. */
#ifdef IP_EXPERIMENTAL

/*! ip_cache_pin_brick() : pins global brick `g` and fills *brick. On a miss the brick is read
 *  from the file, its checksum verified and decoded; a bad brick is reported (IP_ERR_CHECKSUM,
 *  IP_ERR_CORRUPT or IP_ERR_IO naming it) and nothing is pinned, and the caller may go on with
 *  other bricks. @return IP_OK, IP_ERR_CHECKSUM, IP_ERR_CORRUPT, IP_ERR_IO, IP_ERR_ARGUMENT or
 *  IP_ERR_NOMEM. */
IP_API ip_status ip_cache_pin_brick(ip_cache *cache, uint64_t g, ip_brick *brick, ip_error *err);

/*! ip_cache_unpin_brick() : releases one pin taken by ip_cache_pin_brick(). */
IP_API void ip_cache_unpin_brick(ip_cache *cache, const ip_brick *brick);

/*! ip_cache_trim() : evicts unpinned bricks, least recently used first, until at most
 *  `keep_bytes` of decoded bricks stay resident (0: all that are not pinned), and frees their
 *  memory; for a caller done with them for now (before rendering a large mesh, say). These
 *  evictions are not counted in `evictions`, which counts those made for room.
 *  Thread-safe. @return the decoded bytes freed. */
IP_API uint64_t ip_cache_trim(ip_cache *cache, uint64_t keep_bytes);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif
