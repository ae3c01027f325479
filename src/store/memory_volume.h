/* SPDX-License-Identifier: BSD-3-Clause */
/* A volume in the caller's memory as a store sees it: its level 0 where the caller keeps it,
 * its coarser levels built once and held, the summaries of every brick. Internal. */
#ifndef ISOPROP_MEMORY_VOLUME_H
#define ISOPROP_MEMORY_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/layout.h"

typedef struct ip__memory_volume {
    const unsigned char *samples;         /* level 0's sample (0,0,0): the caller's */
    ptrdiff_t strides[3];                 /* level 0's, bytes */
    unsigned char *levels[IP_MAX_LEVELS]; /* levels 1.. (x fastest, contiguous), owned */
    uint64_t held_bytes;                  /* bytes of levels */
} ip__memory_volume;

/* The first sample of level 0 that is not finite (float32 only): 1 and its coordinates in
 * xyz, or 0 when every one is. Runs on `threads` threads. */
int ip__memory_volume_find_nonfinite(const ip__memory_volume *m, const ip_layout *l,
                                     unsigned threads, uint32_t xyz[3]);

/* Builds the coarser levels of `l` from level 0 (as the bricker samples them), then every
 * brick's range (2 floats per global brick index into brick_ranges) and sub-block ranges
 * (2 * (B/s)^3 floats per brick into subblock_ranges), as ip__summarise_brick() gives them,
 * on `threads` threads. @return IP_OK or IP_ERR_NOMEM (nothing else written to err). */
ip_status ip__memory_volume_build(ip__memory_volume *m, const ip_layout *l, unsigned threads,
                                  float *brick_ranges, float *subblock_ranges);

/* Copies the samples of `level` in the box origin + extent (level coordinates) into dst, x
 * fastest, contiguous. */
void ip__memory_volume_gather(const ip__memory_volume *m, const ip_layout *l, uint32_t level,
                              const uint32_t origin[3], const uint32_t extent[3], void *dst);

/* Frees the levels the volume holds (not the caller's samples). */
void ip__memory_volume_free(ip__memory_volume *m);

#endif
