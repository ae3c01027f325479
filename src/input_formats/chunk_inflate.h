/* SPDX-License-Identifier: BSD-3-Clause */
/* Internal to the input component: a layer of gzip (zlib) chunks, as HDF5's deflate filter
 * (after its shuffle filter or not) stores them, inflated on several threads and put in place
 * in a slab of whole planes. No HDF5 here: the caller reads the stored chunks. */
#ifndef ISOPROP_CHUNK_INFLATE_H
#define ISOPROP_CHUNK_INFLATE_H

#include <stddef.h>
#include <stdint.h>

#include "pool.h"

typedef struct ip__chunk_layer {
    size_t sample;                  /* bytes a sample */
    uint64_t chunk[3];              /* a chunk's extent along z, y, x (samples) */
    uint64_t planes, rows, columns; /* the slab: planes (<= chunk[0]) of rows x columns */
    uint32_t chunks_y, chunks_x;    /* chunks across the slab; chunk i is (i / chunks_x,
                                       i % chunks_x) */
    int shuffled;                   /* the bytes were shuffled before deflate */
    unsigned char *const *packed;   /* chunk i's stored bytes ... */
    const size_t *packed_size;      /* ... and their count */
    unsigned char *slab;            /* planes x rows x columns samples, written */
} ip__chunk_layer;

/*! ip__chunk_layer_scratch() : bytes of scratch memory ip__chunk_layer_inflate() needs for a
 *  pool of `threads` threads. */
size_t ip__chunk_layer_scratch(const ip__chunk_layer *layer, unsigned threads);

/*! ip__chunk_layer_inflate() : inflates every chunk of `layer` (on the pool's threads) into
 *  its place in layer->slab. Returns 0, or the zlib error of the first chunk that does not
 *  inflate to exactly a chunk's bytes, its index in *bad. */
int ip__chunk_layer_inflate(const ip__chunk_layer *layer, ip__pool *pool, unsigned char *scratch,
                            uint32_t *bad);

#endif
