/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: the histogram of a brick file's sample values, to choose an isovalue.
 *
 * ip_histogram_compute() counts the samples of one level of the pyramid in bins spread evenly
 * over the file's value range, reading and decoding that level's bricks through the store (a
 * constant brick counts without reading anything). Each sample is counted once: a brick's
 * + face layer, shared with its neighbour, is counted by the neighbour, except on the
 * volume's last face. For each bin it also counts, from the summaries alone, the sub-blocks
 * of that level an isovalue at the bin's lower edge would cross (min < edge <= max, the rule
 * of an active cell): where the surface would be large. A coarse level is fast on huge files
 * (ip_histogram_default_level()); level 0 counts every sample.
 * The functions may be called from several threads at once on the same store.
 */
#ifndef ISOPROP_HISTOGRAM_H
#define ISOPROP_HISTOGRAM_H

#include <stdint.h>

#include "isoprop/layout.h"
#include "isoprop/status.h"
#include "isoprop/store.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ip_histogram_default_level()'s bound: the finest level with at most this many samples. */
#define IP_HISTOGRAM_DEFAULT_SAMPLES (16u * 1024u * 1024u)
#define IP_HISTOGRAM_DEFAULT_BINS 64u
#define IP_HISTOGRAM_MAX_BINS 65536u

/* One bin: the samples v with lo <= v < hi (the last bin also holds v == hi). */
typedef struct ip_histogram_bin {
    double lo, hi;             /* sample values */
    uint64_t count;            /* samples of the level in the bin */
    uint64_t active_subblocks; /* sub-blocks of the level with min < lo <= max */
} ip_histogram_bin;

/* A histogram of one level. Owned by the caller, released with ip_histogram_free(). */
typedef struct ip_histogram {
    uint32_t level;
    uint64_t samples;   /* the level's samples: dims[0] * dims[1] * dims[2] */
    uint64_t unbinned;  /* samples in no bin (NaN): samples - the sum of the counts */
    uint64_t subblocks; /* sub-blocks of the level that hold cells */
    uint64_t bricks_read, bricks_constant; /* bricks decoded, bricks counted from the summary */
    double lo, hi;                         /* the file's value range the bins cover */
    uint32_t bin_count;
    ip_histogram_bin *bins; /* bin_count bins, increasing */
} ip_histogram;

/*! ip_histogram_default_level() : the finest level of `layout` with at most `max_samples`
 *  samples (IP_HISTOGRAM_DEFAULT_SAMPLES keeps a histogram under a second or so), or the
 *  coarsest level when every level has more. */
IP_API uint32_t ip_histogram_default_level(const ip_layout *layout, uint64_t max_samples);

/*! ip_histogram_compute() : the histogram of level `level` (< level_count) of `store` in at
 *  most `bins` bins (1 .. IP_HISTOGRAM_MAX_BINS) over the file's value range [value_min,
 *  value_max]. Bins have equal widths; for an integer sample type the width is a whole number
 *  and each bin holds whole values (a uint8 file with 64 bins: 4 values a bin; a range of 10
 *  values with 64 bins: 10 bins of one value). A file of one value has one bin. *out is the
 *  caller's, released with ip_histogram_free().
 *  @return IP_OK; IP_ERR_ARGUMENT for a level or bin count out of range; IP_ERR_UNSUPPORTED
 *  when the value range is not finite; IP_ERR_NOMEM; the errors of ip_store_read_brick()
 *  (IP_ERR_IO, IP_ERR_CHECKSUM, IP_ERR_CORRUPT) naming the brick. */
IP_API ip_status ip_histogram_compute(const ip_store *store, uint32_t level, uint32_t bins,
                                      ip_histogram **out, ip_error *err);

/*! ip_histogram_free() : releases a histogram (NULL is allowed). */
IP_API void ip_histogram_free(ip_histogram *histogram);

#ifdef __cplusplus
}
#endif
#endif
