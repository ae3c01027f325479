/* SPDX-License-Identifier: BSD-3-Clause */
/* Full extraction welded as it goes: every active cell of a level as an indexed mesh, each
 * vertex keyed by the grid edge it lies on (or the sample it sits on), welded brick by brick in
 * a dense table on all threads, then the vertices on brick faces joined across bricks in brick
 * order. The result is ip_mesh_weld()'s of ip_extract_full()'s soup, vertex for vertex. */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "extract_full.h"
#include "internal.h"
#include "isoprop/engine.h"
#include "pool.h"
#include "propagate.h"

#define MAX_VERTICES (UINT64_C(0xffffffff) - 1) /* as ip_mesh_weld(): indices are uint32 */
#define NO_KEY UINT64_MAX

/* A worker's vertices, triangles and brick-face vertices, in the order of its bricks. */
typedef struct indexed_part {
    float *positions; /* 3 per vertex */
    float *sums;      /* 3 per vertex: the sum of its corners' unpacked normals */
    int16_t *first;   /* 3 per vertex: its first corner's packed normal */
    float *values;    /* per vertex: the larger sample of its edge (its sample's, on one) */
    uint64_t vertices, vertex_capacity;
    uint32_t *indices; /* 3 per triangle: the worker's own vertex numbers */
    uint64_t triangles, triangle_capacity;
    uint64_t *shared_key; /* per vertex on a brick face: its level-wide key */
    uint32_t *shared_vertex;
    uint32_t *shared_joined; /* per brick-face vertex: the joined vertex an earlier brick made
                                of it, or UINT32_MAX where it is new (join_plan()) */
    uint64_t shared, shared_capacity;
} indexed_part;

/* Where one brick's output starts in its worker's part. */
typedef struct indexed_chunk {
    uint64_t brick; /* level-local index */
    uint64_t vertex, triangle, shared;
    uint64_t joined_vertex, joined_triangle; /* where its new vertices and its triangles go in
                                                the joined mesh (join_plan()) */
} indexed_chunk;

typedef struct indexed_worker {
    ip_cache *cache;
    float iso;
    uint32_t level;
    int keep_degenerate;
    atomic_uint_fast64_t *next;
    ip_sampler sampler;
    uint32_t *table; /* per brick-local key: 1 + the worker's vertex number (stale when below
                        the chunk's first vertex) */
    indexed_part part;
    indexed_chunk *chunks;
    uint64_t chunk_count, chunk_capacity;
    uint64_t dropped;
    ip_engine_counts counts;
    ip_status status;
} indexed_worker;

/* The brick being welded: its samples and the first vertex of its chunk. */
typedef struct brick_frame {
    uint32_t origin[3], extent[3];
    uint64_t first_vertex;
} brick_frame;

/* The array at `array` of *capacity elements of `size` bytes holding `needed`
 * (ip__array_reserve(), from 4096 elements). */
static ip_status grow(void *array, uint64_t *capacity, uint64_t needed, size_t size)
{
    return ip__array_reserve(array, capacity, needed, size, 4096);
}

/* Room for the vertices (and brick-face vertices) and triangles of one more cell. */
static ip_status part_reserve(indexed_part *p, uint64_t triangles)
{
    uint64_t more = 12; /* a cell adds at most one vertex per edge */
    if (p->vertices + more > MAX_VERTICES)
        return IP_ERR_ARGUMENT;
    if (p->vertices + more > p->vertex_capacity) {
        uint64_t cap = p->vertex_capacity, c = cap, need = p->vertices + more;
        if (grow(&p->positions, &c, need, 3 * sizeof(float)) != IP_OK ||
            (c = cap, grow(&p->sums, &c, need, 3 * sizeof(float))) != IP_OK ||
            (c = cap, grow(&p->first, &c, need, 3 * sizeof(int16_t))) != IP_OK ||
            (c = cap, grow(&p->values, &c, need, sizeof(float))) != IP_OK)
            return IP_ERR_NOMEM;
        p->vertex_capacity = c;
    }
    if (p->shared + more > p->shared_capacity) {
        uint64_t cap = p->shared_capacity, c = cap, need = p->shared + more;
        if (grow(&p->shared_key, &c, need, sizeof(uint64_t)) != IP_OK ||
            (c = cap, grow(&p->shared_vertex, &c, need, sizeof(uint32_t))) != IP_OK)
            return IP_ERR_NOMEM;
        p->shared_capacity = c;
    }
    return grow(&p->indices, &p->triangle_capacity, p->triangles + triangles, 3 * sizeof(uint32_t));
}

static void part_free(indexed_part *p)
{
    free(p->positions);
    free(p->sums);
    free(p->first);
    free(p->values);
    free(p->indices);
    free(p->shared_key);
    free(p->shared_vertex);
    free(p->shared_joined);
}

/* One crossed edge of a cell: the key of its vertex in the brick's table, whether that vertex
 * may be shared with another brick (then its level-wide key), and its value. */
typedef struct edge_key {
    uint32_t local;
    uint64_t global; /* NO_KEY inside the brick */
    float value;
} edge_key;

/* The key of the vertex at points[e] of `cell`: the sample it sits on where its coordinate
 * along the edge is a corner's (kind 3), else the edge (kind = its axis), at the edge's low
 * sample; so that two corners at one position have one key, as welding by position joins them. */
static edge_key key_of(const ip_sampler *s, const brick_frame *b, const uint32_t cell[3],
                       const float values[8], unsigned e, const float point[3], const float lo[3],
                       const float hi[3])
{
    unsigned axis = e >> 2, c0 = ip__mc_edge_corners[e][0], c1 = ip__mc_edge_corners[e][1];
    unsigned kind = axis, corner = c0;
    edge_key k = {0, NO_KEY, values[c0] > values[c1] ? values[c0] : values[c1]};
    if (point[axis] == lo[axis] || point[axis] == hi[axis]) {
        kind = 3;
        corner = point[axis] == lo[axis] ? c0 : c1;
        k.value = values[corner];
    }
    uint32_t q[3];
    int face = 0;
    for (unsigned a = 0; a < 3; a++) {
        q[a] = cell[a] + ((corner >> a) & 1u) - b->origin[a];
        face |= (a != kind) & (q[a] == 0 || q[a] + 1 == b->extent[a]);
    }
    k.local = 4 * (q[0] + b->extent[0] * (q[1] + b->extent[1] * q[2])) + kind;
    if (face) {
        uint64_t p[3] = {b->origin[0] + q[0], b->origin[1] + q[1], b->origin[2] + q[2]};
        k.global = 4 * (p[0] + (uint64_t)s->dims[0] * (p[1] + (uint64_t)s->dims[1] * p[2])) + kind;
    }
    return k;
}

/* The worker's vertex for key k (point p, packed normal n), added when the brick has none. */
static uint32_t vertex_for(indexed_worker *w, const brick_frame *b, const edge_key *k,
                           const float p[3], const int16_t n[3])
{
    indexed_part *part = &w->part;
    uint32_t stored = w->table[k->local];
    if (stored > b->first_vertex)
        return stored - 1;
    uint64_t v = part->vertices++;
    w->table[k->local] = (uint32_t)(v + 1);
    for (int a = 0; a < 3; a++) {
        part->positions[3 * v + a] = p[a] + 0.0f; /* -0 as +0, as ip_mesh_weld() */
        part->first[3 * v + a] = n[a];
        part->sums[3 * v + a] = 0.0f;
    }
    part->values[v] = k->value;
    if (k->global != NO_KEY) {
        part->shared_key[part->shared] = k->global;
        part->shared_vertex[part->shared++] = (uint32_t)v;
    }
    return (uint32_t)v;
}

/* Welds the triangles of one active cell into the worker's part. */
static ip_status weld_cell(indexed_worker *w, const brick_frame *b, const uint32_t cell[3],
                           const float values[8], unsigned mc)
{
    ip_sampler *s = &w->sampler;
    float lo[3], hi[3], points[12][3], normals[12][3];
    ip__sampler_cell_box(s, cell, lo, hi);
    unsigned crossed = ip__mc_cell_edge_points(values, mc, w->iso, lo, hi, points);
    if (ip__sampler_cell_normals(s, cell, values, mc, w->iso, lo, hi, normals) < 0)
        return s->status;
    edge_key keys[12];
    int16_t packed[12][3];
    for (unsigned left = crossed; left; left &= left - 1) {
        unsigned e = ip__lowest_bit(left);
        keys[e] = key_of(s, b, cell, values, e, points[e], lo, hi);
        for (int a = 0; a < 3; a++)
            packed[e][a] = ip_normal_pack(normals[e][a]);
    }
    const int8_t *row = s->mc_rows[mc];
    int n = ip__mc_triangle_count[mc];
    indexed_part *p = &w->part;
    ip_status st = part_reserve(p, (uint64_t)n);
    if (st != IP_OK)
        return st;
    for (int t = 0; t < n; t++) {
        const int8_t *e = row + 3 * t;
        if (!w->keep_degenerate &&
            (keys[e[0]].local == keys[e[1]].local || keys[e[1]].local == keys[e[2]].local ||
             keys[e[0]].local == keys[e[2]].local)) {
            w->dropped++;
            continue;
        }
        for (int k = 0; k < 3; k++) {
            uint32_t v = vertex_for(w, b, &keys[e[k]], points[e[k]], packed[e[k]]);
            p->indices[3 * p->triangles + (uint64_t)k] = v;
            for (int a = 0; a < 3; a++)
                p->sums[3 * (uint64_t)v + a] += ip_normal_unpack(packed[e[k]][a]);
        }
        p->triangles++;
    }
    w->counts.triangles += (uint64_t)n;
    w->counts.cells++;
    return IP_OK;
}

/* Welds the active cells of brick g, sub-block by sub-block. */
static ip_status weld_brick(indexed_worker *w, uint64_t g)
{
    ip_sampler *s = &w->sampler;
    const ip_layout *l = s->layout;
    const float *ranges = ip_store_subblock_ranges(ip_cache_store(s->cache), g);
    uint32_t level, brick[3];
    brick_frame b;
    ip_brick_coords(l, g, &level, brick);
    ip_brick_extent(l, level, brick, b.origin, b.extent);
    b.first_vertex = w->part.vertices;
    uint32_t per = l->brick_edge / l->subblock_edge, se = l->subblock_edge;
    for (uint32_t i = 0; i < per * per * per; i++) {
        if (!ip__range_active(ranges[2 * i], ranges[2 * i + 1], w->iso))
            continue;
        uint32_t lo[3], hi[3];
        ip__subblock_cells(i, per, se, b.origin, b.extent, lo, hi);
        for (uint32_t z = lo[2]; z < hi[2]; z++)
            for (uint32_t y = lo[1]; y < hi[1]; y++)
                for (uint32_t x = lo[0]; x < hi[0]; x++) {
                    uint32_t cell[3] = {x, y, z};
                    float values[8];
                    unsigned mc;
                    if (ip__sampler_cell_case(s, cell, w->iso, values, &mc) < 0)
                        return s->status;
                    if (mc == 0 || mc == 255)
                        continue;
                    ip_status st = weld_cell(w, &b, cell, values, mc);
                    if (st != IP_OK)
                        return st;
                }
    }
    return IP_OK;
}

static ip_status add_chunk(indexed_worker *w, uint64_t brick)
{
    if (grow(&w->chunks, &w->chunk_capacity, w->chunk_count + 1, sizeof(indexed_chunk)) != IP_OK)
        return IP_ERR_NOMEM;
    w->chunks[w->chunk_count++] =
        (indexed_chunk){brick, w->part.vertices, w->part.triangles, w->part.shared, 0, 0};
    return IP_OK;
}

static void indexed_work(void *user, unsigned index)
{
    indexed_worker *w = (indexed_worker *)user + index;
    const ip_store *store = ip_cache_store(w->cache);
    const ip_level_layout *lv = &ip_store_layout(store)->levels[w->level];
    double start = ip_now_seconds();
    for (uint64_t i; w->status == IP_OK && ip__next_active_brick(store, lv, w->next, w->iso, &i);) {
        w->status = add_chunk(w, i);
        if (w->status == IP_OK)
            w->status = weld_brick(w, lv->first_brick + i);
        ip__sampler_release(&w->sampler); /* a brick at a time */
    }
    w->counts.extraction_seconds = ip_now_seconds() - start;
}

/* A chunk in the joined order: its worker and its number there. */
typedef struct chunk_ref {
    unsigned worker;
    uint64_t chunk;
} chunk_ref;

/* The joining: the joined mesh and its per-vertex sums and values, the chunks in brick order,
 * and the workers' vertex numbers in the joined mesh. */
typedef struct joiner {
    ip_indexed_mesh *out;
    float *sums, *values;
    indexed_worker *w;
    chunk_ref *order;
    uint64_t chunks;
    uint32_t *map;             /* per vertex of every worker, worker after worker */
    uint64_t *map_of;          /* per worker: its first entry in map */
    atomic_uint_fast64_t next; /* the next chunk of `order` to copy (join_work()) */
    unsigned parts;            /* finish_normals()' */
} joiner;

static uint64_t key_hash(uint64_t k)
{
    k *= UINT64_C(0x9e3779b97f4a7c15);
    return k ^ (k >> 29);
}

/* The end of chunk c of worker w: its vertices, triangles and brick-face vertices. */
static void chunk_end(const indexed_worker *w, uint64_t c, uint64_t end[3])
{
    int last = c + 1 == w->chunk_count;
    const indexed_chunk *next = &w->chunks[c + 1];
    end[0] = last ? w->part.vertices : next->vertex;
    end[1] = last ? w->part.triangles : next->triangle;
    end[2] = last ? w->part.shared : next->shared;
}

/* Sequentially, in brick order: which brick-face vertices an earlier brick made (their
 * shared_joined), and where each chunk's new vertices and its triangles go. Counts the
 * joined vertices and triangles into out. `keys` and `slots`: a hash table of mask + 1 slots,
 * keys NO_KEY. */
static void join_plan(joiner *j, uint64_t *keys, uint32_t *slots, uint64_t mask)
{
    uint64_t vertices = 0, triangles = 0;
    for (uint64_t o = 0; o < j->chunks; o++) {
        indexed_worker *w = &j->w[j->order[o].worker];
        indexed_chunk *ch = &w->chunks[j->order[o].chunk];
        uint64_t end[3], repeated = 0;
        chunk_end(w, j->order[o].chunk, end);
        ch->joined_vertex = vertices;
        ch->joined_triangle = triangles;
        for (uint64_t s = ch->shared; s < end[2]; s++) {
            uint64_t key = w->part.shared_key[s], i = key_hash(key) & mask;
            while (keys[i] != NO_KEY && keys[i] != key)
                i = (i + 1) & mask;
            w->part.shared_joined[s] = keys[i] == key ? slots[i] : UINT32_MAX;
            if (keys[i] == key) {
                repeated++;
                continue;
            }
            keys[i] = key;
            slots[i] = (uint32_t)(vertices + w->part.shared_vertex[s] - ch->vertex - repeated);
        }
        vertices += end[0] - ch->vertex - repeated;
        triangles += end[1] - ch->triangle;
    }
    j->out->vertex_count = vertices;
    j->out->triangle_count = triangles;
}

/* Copies one chunk's new vertices and its triangles, renumbered, to the joined mesh. */
static void join_chunk(joiner *j, const chunk_ref *ref)
{
    const indexed_worker *w = &j->w[ref->worker];
    const indexed_part *p = &w->part;
    const indexed_chunk *ch = &w->chunks[ref->chunk];
    uint32_t *map = j->map + j->map_of[ref->worker];
    ip_indexed_mesh *m = j->out;
    uint64_t end[3], g = ch->joined_vertex, s = ch->shared;
    chunk_end(w, ref->chunk, end);
    for (uint64_t v = ch->vertex; v < end[0]; v++) {
        if (s < end[2] && p->shared_vertex[s] == v && p->shared_joined[s++] != UINT32_MAX) {
            map[v] = p->shared_joined[s - 1];
            continue;
        }
        map[v] = (uint32_t)g;
        memcpy(m->positions + 3 * g, p->positions + 3 * v, 3 * sizeof(float));
        memcpy(m->normals + 3 * g, p->first + 3 * v, 3 * sizeof(int16_t));
        memcpy(j->sums + 3 * g, p->sums + 3 * v, 3 * sizeof(float));
        j->values[g++] = p->values[v];
    }
    uint32_t *to = m->indices + 3 * ch->joined_triangle;
    for (uint64_t i = 3 * ch->triangle; i < 3 * end[1]; i++)
        *to++ = map[p->indices[i]];
}

static void join_work(void *user, unsigned index)
{
    (void)index;
    joiner *j = user;
    for (uint64_t o; (o = atomic_fetch_add(&j->next, 1)) < j->chunks;)
        join_chunk(j, &j->order[o]);
}

/* Sequentially, in brick order: adds to each brick-face vertex that an earlier brick made the
 * normals of its corners in the later bricks. */
static void join_repeated_sums(joiner *j)
{
    for (uint64_t o = 0; o < j->chunks; o++) {
        const indexed_worker *w = &j->w[j->order[o].worker];
        const indexed_chunk *ch = &w->chunks[j->order[o].chunk];
        uint64_t end[3];
        chunk_end(w, j->order[o].chunk, end);
        for (uint64_t s = ch->shared; s < end[2]; s++) {
            uint64_t to = w->part.shared_joined[s], v = w->part.shared_vertex[s];
            if (to != UINT32_MAX)
                for (int a = 0; a < 3; a++)
                    j->sums[3 * to + a] += w->part.sums[3 * v + a];
        }
    }
}

/* Each vertex's normal: its corners' average, normalised; the first corner's where they
 * cancel out (as ip_mesh_weld()): part `index` of j->parts of the vertices. */
static void finish_normals(void *user, unsigned index)
{
    joiner *j = user;
    ip_indexed_mesh *m = j->out;
    uint64_t first = m->vertex_count * index / j->parts;
    uint64_t end = m->vertex_count * (index + 1) / j->parts;
    for (uint64_t v = first; v < end; v++) {
        const float *s = j->sums + 3 * v;
        float length = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        if (length > 0.0f)
            for (int k = 0; k < 3; k++)
                m->normals[3 * v + k] = ip_normal_pack(s[k] / length);
    }
}

/* The chunks of every worker in brick order into j->order (allocated). */
static ip_status join_order(joiner *j, unsigned threads)
{
    j->chunks = 0;
    for (unsigned t = 0; t < threads; t++)
        j->chunks += j->w[t].chunk_count;
    j->order = malloc((j->chunks + 1) * sizeof *j->order);
    uint64_t *cursor = calloc(threads, sizeof *cursor);
    if (!j->order || !cursor) {
        free(cursor);
        return IP_ERR_NOMEM;
    }
    for (uint64_t o = 0; o < j->chunks; o++) {
        unsigned best = threads;
        for (unsigned t = 0; t < threads; t++)
            if (cursor[t] < j->w[t].chunk_count &&
                (best == threads ||
                 j->w[t].chunks[cursor[t]].brick < j->w[best].chunks[cursor[best]].brick))
                best = t;
        j->order[o] = (chunk_ref){best, cursor[best]++};
    }
    free(cursor);
    return IP_OK;
}

/* The arrays of the joining, for `vertices` and `triangles` at most, and the hash table of
 * `shared` brick-face vertices that join_plan() uses (*keys, *slots, mask + 1 slots). */
static ip_status joiner_alloc(joiner *j, unsigned threads, uint64_t vertices, uint64_t triangles,
                              uint64_t shared, uint64_t **keys, uint32_t **slots, uint64_t *mask)
{
    ip_indexed_mesh *m = j->out;
    uint64_t slot_count = 1024;
    while (slot_count < 2 * shared)
        slot_count *= 2;
    *mask = slot_count - 1;
    if (vertices + 1 > SIZE_MAX / (3 * sizeof(float)) ||
        triangles + 1 > SIZE_MAX / (3 * sizeof(uint32_t)))
        return IP_ERR_NOMEM;
    m->positions = malloc((vertices + 1) * 3 * sizeof(float));
    m->normals = malloc((vertices + 1) * 3 * sizeof(int16_t));
    m->indices = malloc((triangles + 1) * 3 * sizeof(uint32_t));
    j->sums = malloc((vertices + 1) * 3 * sizeof(float));
    j->values = malloc((vertices + 1) * sizeof(float));
    j->map = malloc((vertices + 1) * sizeof(uint32_t));
    j->map_of = malloc(threads * sizeof(uint64_t));
    *keys = malloc(slot_count * sizeof(uint64_t));
    *slots = malloc(slot_count * sizeof(uint32_t));
    int ok = m->positions && m->normals && m->indices && j->sums && j->values && j->map &&
             j->map_of && *keys && *slots;
    for (unsigned t = 0; ok && t < threads; t++) {
        indexed_part *p = &j->w[t].part;
        p->shared_joined = malloc((p->shared + 1) * sizeof(uint32_t));
        ok = p->shared_joined != NULL;
        j->map_of[t] = t ? j->map_of[t - 1] + j->w[t - 1].part.vertices : 0;
    }
    if (!ok)
        return IP_ERR_NOMEM;
    memset(*keys, 0xff, slot_count * sizeof(uint64_t)); /* NO_KEY */
    return IP_OK;
}

/* Joins every worker's chunks, in brick order, into `out` (and *values), copying on the
 * pool's threads. */
static ip_status join_in_brick_order(indexed_worker *w, unsigned threads, ip__pool *pool,
                                     ip_indexed_mesh *out, float **values)
{
    uint64_t vertices = 0, triangles = 0, shared = 0, *keys = NULL, mask = 0;
    uint32_t *slots = NULL;
    for (unsigned t = 0; t < threads; t++) {
        vertices += w[t].part.vertices;
        triangles += w[t].part.triangles;
        shared += w[t].part.shared;
    }
    joiner j = {.out = out, .w = w, .parts = threads};
    atomic_init(&j.next, 0);
    ip_status st = vertices > MAX_VERTICES ? IP_ERR_ARGUMENT
                                           : joiner_alloc(&j, threads, vertices, triangles, shared,
                                                          &keys, &slots, &mask);
    if (st == IP_OK)
        st = join_order(&j, threads);
    if (st == IP_OK) {
        join_plan(&j, keys, slots, mask);
        ip__pool_run(pool, threads, join_work, &j);
        join_repeated_sums(&j);
        ip__pool_run(pool, threads, finish_normals, &j);
        /* give back the slack; a failure to shrink leaves the larger arrays */
        uint64_t v = out->vertex_count + 1;
        (void)ip__array_resize(&out->positions, v, 3 * sizeof(float));
        (void)ip__array_resize(&out->normals, v, 3 * sizeof(int16_t));
        (void)ip__array_resize(&out->indices, out->triangle_count + 1, 3 * sizeof(uint32_t));
        (void)ip__array_resize(&j.values, v, sizeof(float));
    }
    free(keys);
    free(slots);
    free(j.order);
    free(j.map);
    free(j.map_of);
    free(j.sums);
    if (st == IP_OK && values)
        *values = j.values;
    else
        free(j.values);
    return st;
}

ip_status ip_extract_full_indexed(ip_cache *cache, float iso, uint32_t level, unsigned threads,
                                  int keep_degenerate, ip_indexed_mesh *out, float **values,
                                  ip_engine_counts *counts, ip_error *err)
{
    const ip_store *store = ip_cache_store(cache);
    const char *path = ip_store_path(store);
    ip_indexed_mesh_init(out);
    if (values)
        *values = NULL;
    if (level >= ip_store_layout(store)->level_count)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: level %u does not exist", path, level);
    threads = ip_thread_count(threads);
    indexed_worker *w = calloc(threads, sizeof *w);
    if (!w)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    atomic_uint_fast64_t next;
    atomic_init(&next, 0);
    ip_status st = IP_OK;
    uint32_t edge = ip_store_layout(store)->brick_edge + 1;
    size_t table = 4 * (size_t)edge * edge * edge;
    for (unsigned t = 0; t < threads; t++) {
        w[t] = (indexed_worker){.cache = cache,
                                .iso = iso,
                                .level = level,
                                .keep_degenerate = keep_degenerate,
                                .next = &next};
        w[t].table = calloc(table, sizeof(uint32_t));
        if ((ip__sampler_init(&w[t].sampler, cache, level) != IP_OK || !w[t].table) && st == IP_OK)
            st = IP_ERR_NOMEM;
    }
    ip__pool *pool = NULL;
    if (st == IP_OK)
        st = ip__pool_create(threads, &pool, NULL);
    if (st == IP_OK)
        ip__pool_run(pool, threads, indexed_work, w);
    ip_engine_counts c;
    memset(&c, 0, sizeof c);
    for (unsigned t = 0; t < threads; t++) {
        c.cells += w[t].counts.cells;
        c.triangles += w[t].counts.triangles;
        c.extraction_seconds += w[t].counts.extraction_seconds;
        out->dropped_triangles += w[t].dropped;
        if (st == IP_OK && w[t].status != IP_OK) {
            st = w[t].status;
            if (st != IP_ERR_NOMEM && st != IP_ERR_ARGUMENT && err)
                *err = w[t].sampler.error;
        }
    }
    if (st == IP_OK)
        st = join_in_brick_order(w, threads, pool, out, values);
    ip__pool_destroy(pool);
    if (st == IP_ERR_NOMEM)
        ip__fail(err, st, "%s: out of memory", path);
    else if (st == IP_ERR_ARGUMENT)
        ip__fail(err, st, "%s: more than 2^32 - 2 distinct vertices", path);
    for (unsigned t = 0; t < threads; t++) {
        ip__sampler_free(&w[t].sampler);
        free(w[t].table);
        part_free(&w[t].part);
        free(w[t].chunks);
    }
    free(w);
    if (st != IP_OK)
        ip_indexed_mesh_free(out);
    if (counts)
        *counts = c;
    return st;
}
