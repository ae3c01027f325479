/* SPDX-License-Identifier: BSD-3-Clause */
/* Inflating a layer of HDF5 deflate chunks on several threads (chunk_inflate.h): each thread
 * takes the next chunk, inflates it with zlib into its own scratch, undoes the shuffle filter
 * (byte k of every sample was stored together), and copies the chunk's rows that lie inside
 * the dataset into the slab. */
#include <stdatomic.h>
#include <string.h>
#include <zlib.h>

#include "chunk_inflate.h"

typedef struct inflate_run {
    const ip__chunk_layer *layer;
    unsigned char *scratch;
    size_t chunk_bytes;
    atomic_uint next;
    atomic_int error; /* 0, or the first zlib error */
    atomic_uint bad;
} inflate_run;

static size_t chunk_bytes(const ip__chunk_layer *l)
{
    return (size_t)(l->chunk[0] * l->chunk[1] * l->chunk[2]) * l->sample;
}

size_t ip__chunk_layer_scratch(const ip__chunk_layer *layer, unsigned threads)
{
    return 2 * chunk_bytes(layer) * threads;
}

/* HDF5's shuffle: the k-th bytes of all n samples were stored together. */
static void unshuffle(const unsigned char *in, unsigned char *out, size_t n, size_t sample)
{
    for (size_t k = 0; k < sample; k++)
        for (size_t i = 0; i < n; i++)
            out[i * sample + k] = in[k * n + i];
}

/* Chunk i's rows inside the slab, from its decoded samples. */
static void place(const ip__chunk_layer *l, uint32_t i, const unsigned char *chunk)
{
    uint64_t y0 = (i / l->chunks_x) * l->chunk[1], x0 = (i % l->chunks_x) * l->chunk[2];
    uint64_t ny = l->rows - y0 < l->chunk[1] ? l->rows - y0 : l->chunk[1];
    uint64_t nx = l->columns - x0 < l->chunk[2] ? l->columns - x0 : l->chunk[2];
    for (uint64_t z = 0; z < l->planes; z++)
        for (uint64_t y = 0; y < ny; y++)
            memcpy(l->slab + ((z * l->rows + y0 + y) * l->columns + x0) * l->sample,
                   chunk + ((z * l->chunk[1] + y) * l->chunk[2]) * l->sample,
                   (size_t)nx * l->sample);
}

static void inflate_job(void *user, unsigned job)
{
    inflate_run *run = user;
    const ip__chunk_layer *l = run->layer;
    unsigned char *a = run->scratch + 2 * run->chunk_bytes * job, *b = a + run->chunk_bytes;
    uint32_t count = l->chunks_y * l->chunks_x;
    for (uint32_t i = atomic_fetch_add(&run->next, 1); i < count;
         i = atomic_fetch_add(&run->next, 1)) {
        if (atomic_load(&run->error))
            return;
        uLongf made = (uLongf)run->chunk_bytes;
        int z = uncompress(a, &made, l->packed[i], (uLong)l->packed_size[i]);
        if (z == Z_OK && made != run->chunk_bytes)
            z = Z_DATA_ERROR;
        if (z != Z_OK) {
            int none = 0;
            if (atomic_compare_exchange_strong(&run->error, &none, z))
                atomic_store(&run->bad, i);
            return;
        }
        if (l->shuffled && l->sample > 1)
            unshuffle(a, b, run->chunk_bytes / l->sample, l->sample);
        place(l, i, l->shuffled && l->sample > 1 ? b : a);
    }
}

int ip__chunk_layer_inflate(const ip__chunk_layer *layer, ip__pool *pool, unsigned char *scratch,
                            uint32_t *bad)
{
    inflate_run run;
    run.layer = layer;
    run.scratch = scratch;
    run.chunk_bytes = chunk_bytes(layer);
    atomic_init(&run.next, 0);
    atomic_init(&run.error, 0);
    atomic_init(&run.bad, 0);
    ip__pool_run(pool, ip__pool_threads(pool), inflate_job, &run);
    *bad = atomic_load(&run.bad);
    return atomic_load(&run.error);
}
