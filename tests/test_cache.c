/* SPDX-License-Identifier: BSD-3-Clause */
/* The brick cache: exact LRU counts against a reference model, pinning over budget,
 * a corrupted brick, many threads pinning at once (decode-once, counts that agree), and the
 * cell-group ranges of every brick against brute force. */
#include <pthread.h>
#include <stdatomic.h>
#include <sys/stat.h>

#include "cache_prefetch.h"
#include "check.h"
#include "isoprop/cache.h"
#include "isoprop/store.h"
#include "volumes.h"

/* Every level-0 brick of the test volume: 9^3 uint8 samples (729 bytes, padded to 736), then
 * the least and greatest sample of each of its cell groups (8 cells along each edge, in groups
 * of IP_CELL_GROUP). */
#define SAMPLE_BYTES 729
#define GROUPS_PER_EDGE (8 / IP_CELL_GROUP)
#define BRICK_BYTES (736 + GROUPS_PER_EDGE * GROUPS_PER_EDGE * GROUPS_PER_EDGE * 2)

/* What the cases share: the scratch folder, a brick file in it and the store open on it. */
static const char *scratch_dir;
static char scratch_ibv[4200];
static ip_store *the_store;

/* 33^3 uint8 samples, B = 8: 4x4x4 full level-0 bricks, then the pyramid. Sample value
 * depends on the brick so contents can be checked. */
static void make_file(const char *dir, char *ibv, size_t size)
{
    char raw[8192];
    snprintf(raw, sizeof raw, "%s/cells_33x33x33_uint8.raw", dir);
    snprintf(ibv, size, "%s/cells.ibv", dir);
    FILE *f = fopen(raw, "wb");
    REQUIRE(f);
    for (int z = 0; z < 33; z++)
        for (int y = 0; y < 33; y++)
            for (int x = 0; x < 33; x++)
                fputc((x * 3 + y * 5 + z * 7) % 251, f);
    REQUIRE(fclose(f) == 0);
    test_brick_raw(raw, ibv, 8, 4);
}

static int expected_sample(const ip_brick *b, uint32_t x, uint32_t y, uint32_t z)
{
    uint32_t step = 1u << b->level, gx = (b->origin[0] + x) * step, gy = (b->origin[1] + y) * step,
             gz = (b->origin[2] + z) * step;
    gx = gx > 32 ? 32 : gx, gy = gy > 32 ? 32 : gy, gz = gz > 32 ? 32 : gz;
    return (int)((gx * 3 + gy * 5 + gz * 7) % 251);
}

static int brick_ok(const ip_brick *b)
{
    const uint8_t *s = b->samples;
    uint32_t last[3] = {b->extent[0] - 1, b->extent[1] - 1, b->extent[2] - 1};
    return s[0] == expected_sample(b, 0, 0, 0) &&
           s[last[0] + b->extent[0] * (last[1] + b->extent[1] * last[2])] ==
               expected_sample(b, last[0], last[1], last[2]);
}

/* ---- a reference LRU: an array ordered from least to most recently used ---- */
typedef struct lru_model {
    uint64_t items[64];
    int count, capacity;
    uint64_t hits, misses, evictions;
} lru_model;

static void model_access(lru_model *m, uint64_t g)
{
    int found = -1;
    for (int i = 0; i < m->count; i++)
        if (m->items[i] == g)
            found = i;
    if (found >= 0) {
        m->hits++;
        memmove(&m->items[found], &m->items[found + 1], (size_t)(m->count - found - 1) * 8);
        m->count--;
    } else {
        m->misses++;
        if (m->count == m->capacity) {
            memmove(&m->items[0], &m->items[1], (size_t)(m->count - 1) * 8);
            m->count--;
            m->evictions++;
        }
    }
    m->items[m->count++] = g;
}

static void pin_unpin(ip_cache *c, uint64_t g)
{
    ip_brick b;
    ip_error err;
    REQUIRE(ip_cache_pin_brick(c, g, &b, &err) == IP_OK);
    CHECK_EQ(b.index, g);
    CHECK(brick_ok(&b));
    ip_cache_unpin_brick(c, &b);
}

static void test_scripted_lru(void)
{
    const ip_store *s = the_store;
    ip_cache *c;
    ip_cache_stats st;
    REQUIRE(ip_cache_create(s, 4 * BRICK_BYTES, &c, NULL) == IP_OK);
    /* 0 1 2 3 miss; 0 hit; 4 miss evicts 1; 1 miss evicts 2; 0 hit; 3 hit; 2 miss evicts 4 */
    const uint64_t script[] = {0, 1, 2, 3, 0, 4, 1, 0, 3, 2};
    for (size_t i = 0; i < sizeof script / sizeof script[0]; i++)
        pin_unpin(c, script[i]);
    ip_cache_get_stats(c, &st);
    CHECK_MSG(st.hits == 3 && st.misses == 7 && st.evictions == 3,
              "hits %llu misses %llu evictions %llu", (unsigned long long)st.hits,
              (unsigned long long)st.misses, (unsigned long long)st.evictions);
    CHECK_EQ(st.resident_bytes, 4 * BRICK_BYTES);
    CHECK_EQ(st.resident_peak_bytes, 4 * BRICK_BYTES);
    CHECK_EQ(st.bricks_touched, 5);
    CHECK_EQ(st.bytes_decompressed, 7 * SAMPLE_BYTES);
    CHECK_EQ(st.pinned_bytes, 0);
    CHECK_EQ(st.over_budget_pins, 0);
    /* brick 4 was evicted last: asking again is a miss; brick 2 (just used) is a hit */
    pin_unpin(c, 2);
    pin_unpin(c, 4);
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.hits, 4);
    CHECK_EQ(st.misses, 8);
    CHECK_EQ(st.evictions, 4);
    /* trimming: keep one brick's worth (the most recent, 4), then all but the pinned one */
    CHECK_EQ(ip_cache_trim(c, BRICK_BYTES), 3 * BRICK_BYTES);
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.resident_bytes, BRICK_BYTES);
    CHECK_EQ(st.resident_bricks, 1);
    CHECK_EQ(st.evictions, 4);
    pin_unpin(c, 4);
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.hits, 5);
    CHECK_EQ(st.misses, 8);
    ip_brick held;
    REQUIRE(ip_cache_pin_brick(c, 0, &held, NULL) == IP_OK);
    CHECK_EQ(ip_cache_trim(c, 0), BRICK_BYTES); /* brick 4 goes, pinned brick 0 stays */
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.resident_bytes, BRICK_BYTES);
    CHECK_EQ(st.pinned_bytes, BRICK_BYTES);
    CHECK(brick_ok(&held));
    ip_cache_unpin_brick(c, &held);
    CHECK_EQ(ip_cache_trim(c, 0), BRICK_BYTES);
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.resident_bytes, 0);
    CHECK_EQ(st.resident_bricks, 0);
    CHECK_EQ(st.evictions, 4);
    pin_unpin(c, 0); /* loads again */
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.misses, 10);
    CHECK_EQ(st.resident_bytes, BRICK_BYTES);
    ip_cache_destroy(c);

    /* a long pseudo-random sequence against the model, for several budgets */
    for (int capacity = 1; capacity <= 9; capacity += 4) {
        lru_model m = {{0}, 0, capacity, 0, 0, 0};
        REQUIRE(ip_cache_create(s, (uint64_t)capacity * BRICK_BYTES, &c, NULL) == IP_OK);
        uint64_t x = 12345;
        for (int i = 0; i < 5000; i++) {
            x = x * 6364136223846793005ull + 1442695040888963407ull;
            uint64_t g = (x >> 33) % 12; /* a working set a little larger than the budget */
            model_access(&m, g);
            pin_unpin(c, g);
        }
        ip_cache_get_stats(c, &st);
        CHECK_MSG(st.hits == m.hits && st.misses == m.misses && st.evictions == m.evictions,
                  "capacity %d: cache %llu/%llu/%llu model %llu/%llu/%llu", capacity,
                  (unsigned long long)st.hits, (unsigned long long)st.misses,
                  (unsigned long long)st.evictions, (unsigned long long)m.hits,
                  (unsigned long long)m.misses, (unsigned long long)m.evictions);
        CHECK_LE(st.resident_peak_bytes, (uint64_t)capacity * BRICK_BYTES);
        ip_cache_destroy(c);
    }
}

static void test_pinning(void)
{
    const ip_store *s = the_store;
    ip_cache *c;
    ip_cache_stats st;
    ip_brick held[5];
    ip_error err;
    REQUIRE(ip_cache_create(s, 4 * BRICK_BYTES, &c, NULL) == IP_OK);
    for (uint64_t g = 0; g < 5; g++)
        REQUIRE(ip_cache_pin_brick(c, g, &held[g], &err) == IP_OK);
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.over_budget_pins, 1); /* the fifth found every resident brick pinned */
    CHECK_EQ(st.resident_bytes, 5 * BRICK_BYTES);
    CHECK_EQ(st.pinned_bytes, 5 * BRICK_BYTES);
    CHECK_EQ(st.evictions, 0);
    /* pinned bricks survive other traffic */
    pin_unpin(c, 6);
    pin_unpin(c, 7);
    int intact = 1;
    for (int i = 0; i < 5; i++)
        intact &= brick_ok(&held[i]) && held[i].index == (uint64_t)i;
    CHECK(intact);
    /* a second pin of a pinned brick is a hit on the same samples */
    ip_brick again;
    REQUIRE(ip_cache_pin_brick(c, 2, &again, &err) == IP_OK);
    CHECK_EQ(again.samples, held[2].samples);
    ip_cache_unpin_brick(c, &again);
    for (int i = 0; i < 5; i++)
        ip_cache_unpin_brick(c, &held[i]);
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.pinned_bytes, 0);
    /* unpinned, the next miss brings the cache back within its budget */
    pin_unpin(c, 20);
    ip_cache_get_stats(c, &st);
    CHECK_MSG(st.resident_bytes <= 4 * BRICK_BYTES, "resident %llu",
              (unsigned long long)st.resident_bytes);
    ip_cache_destroy(c);
}

static void test_corrupt_brick(void)
{
    const char *dir = scratch_dir, *ibv = scratch_ibv;
    char bad[4200];
    snprintf(bad, sizeof bad, "%s/corrupt.ibv", dir);
    char cmd[9000];
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", ibv, bad);
    REQUIRE(system(cmd) == 0);
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open(bad, &s, &err) == IP_OK);
    /* flip a byte in the middle of brick 21's payload (a level-0 brick inside the volume) */
    ip_brick_entry e;
    ip_store_brick_entry(s, 21, &e);
    REQUIRE(e.stored_size > 0);
    ip_store_close(s);
    FILE *f = fopen(bad, "r+b");
    REQUIRE(f && fseek(f, (long)(e.offset + e.stored_size / 2), SEEK_SET) == 0);
    int byte = fgetc(f);
    REQUIRE(fseek(f, (long)(e.offset + e.stored_size / 2), SEEK_SET) == 0);
    fputc(byte ^ 0x40, f);
    fclose(f);
    REQUIRE(ip_store_open(bad, &s, &err) == IP_OK); /* the summary is intact */
    ip_cache *c;
    REQUIRE(ip_cache_create(s, 1 << 20, &c, NULL) == IP_OK);
    ip_brick b;
    CHECK_EQ(ip_cache_pin_brick(c, 21, &b, &err), IP_ERR_CHECKSUM);
    CHECK_CONTAINS(err.message, "corrupt.ibv");
    CHECK_CONTAINS(err.message, "brick 21");
    int others = 1;
    for (uint64_t g = 0; g < ip_store_layout(s)->brick_count; g++) {
        if (g == 21)
            continue;
        if (ip_cache_pin_brick(c, g, &b, &err) != IP_OK || !brick_ok(&b))
            others = 0;
        else
            ip_cache_unpin_brick(c, &b);
    }
    CHECK(others);
    ip_cache_stats st;
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.errors, 1);
    CHECK_EQ(st.misses, ip_store_layout(s)->brick_count - 1);
    CHECK_EQ(ip_cache_pin_brick(c, 21, &b, &err), IP_ERR_CHECKSUM); /* still reported */
    ip_cache_destroy(c);
    ip_store_close(s);
}

/* ---- threads ---- */
typedef struct hammer {
    ip_cache *cache;
    uint64_t bricks;
    int seed, rounds;
    atomic_int bad;
    atomic_uint_fast64_t pins;
} hammer;

static void *hammer_thread(void *p)
{
    hammer *h = p;
    uint64_t x = (uint64_t)h->seed * 7919u + 1;
    ip_error err;
    for (int i = 0; i < h->rounds; i++) {
        x = x * 6364136223846793005ull + 1442695040888963407ull;
        uint64_t g = (x >> 33) % h->bricks;
        ip_brick b[2];
        int n = 1 + (int)((x >> 20) & 1); /* sometimes hold two bricks at once */
        for (int k = 0; k < n; k++) {
            if (ip_cache_pin_brick(h->cache, (g + (uint64_t)k) % h->bricks, &b[k], &err) != IP_OK ||
                !brick_ok(&b[k]))
                atomic_store(&h->bad, 1);
            atomic_fetch_add(&h->pins, 1);
        }
        for (int k = 0; k < n; k++)
            ip_cache_unpin_brick(h->cache, &b[k]);
    }
    return NULL;
}

static void run_hammer(const ip_store *s, uint64_t budget, int threads, int rounds,
                       ip_cache_stats *st, int *bad, uint64_t *pins)
{
    ip_cache *cache;
    REQUIRE(ip_cache_create(s, budget, &cache, NULL) == IP_OK);
    pthread_t t[16];
    hammer each[16];
    for (int i = 0; i < threads; i++) {
        memset(&each[i], 0, sizeof each[i]);
        each[i].cache = cache;
        each[i].bricks = ip_store_layout(s)->brick_count;
        each[i].rounds = rounds;
        each[i].seed = i + 1;
        atomic_init(&each[i].bad, 0);
        atomic_init(&each[i].pins, 0);
        REQUIRE(pthread_create(&t[i], NULL, hammer_thread, &each[i]) == 0);
    }
    *bad = 0;
    *pins = 0;
    for (int i = 0; i < threads; i++) {
        pthread_join(t[i], NULL);
        *bad |= atomic_load(&each[i].bad);
        *pins += atomic_load(&each[i].pins);
    }
    ip_cache_get_stats(cache, st);
    ip_cache_destroy(cache);
}

static void test_threads(void)
{
    const ip_store *s = the_store;
    const ip_layout *l = ip_store_layout(s);
    ip_cache_stats st;
    int bad;
    uint64_t pins;
    /* a budget that holds everything: every brick is decoded exactly once, however many
     * threads miss on it together */
    run_hammer(s, 64ull << 20, 8, 3000, &st, &bad, &pins);
    CHECK(!bad);
    CHECK_EQ(st.hits + st.misses, pins);
    CHECK_MSG(st.misses == st.bricks_touched, "misses %llu touched %llu",
              (unsigned long long)st.misses, (unsigned long long)st.bricks_touched);
    CHECK_EQ(st.bricks_touched, l->brick_count);
    CHECK_EQ(st.evictions, 0);
    CHECK_EQ(st.errors, 0);
    CHECK_EQ(st.pinned_bytes, 0);
    /* a budget for a sixth of the bricks: constant eviction under contention */
    run_hammer(s, 12 * BRICK_BYTES, 8, 3000, &st, &bad, &pins);
    CHECK(!bad);
    CHECK_EQ(st.hits + st.misses, pins);
    CHECK_EQ(st.misses, st.resident_bricks + st.evictions);
    CHECK_EQ(st.pinned_bytes, 0);
    CHECK_EQ(st.errors, 0);
    CHECK_MSG(st.resident_bytes <= 12 * BRICK_BYTES || st.over_budget_pins > 0, "resident %llu",
              (unsigned long long)st.resident_bytes);
    CHECK_LE(st.resident_peak_bytes, (12 + 16) * BRICK_BYTES); /* budget + what 8 threads pin */
}

/* The cell-group ranges (ip_brick.group_ranges) of every brick of every level, against the
 * least and greatest corner of the group's cells sample by sample; dims whose bricks end with
 * cell counts that IP_CELL_GROUP does not divide (a last group narrower), int16 samples. */
static void test_group_ranges(void)
{
    const char *dir = scratch_dir;
    char raw[4200], ibv[4200];
    snprintf(raw, sizeof raw, "%s/groups_27x22x19_int16.raw", dir);
    snprintf(ibv, sizeof ibv, "%s/groups.ibv", dir);
    FILE *f = fopen(raw, "wb");
    REQUIRE(f);
    uint64_t x = 88172645463325252ull;
    for (int i = 0; i < 27 * 22 * 19; i++) {
        test_xorshift(&x);
        int16_t v = (int16_t)((int)(x % 4001) - 2000);
        REQUIRE(fwrite(&v, sizeof v, 1, f) == 1);
    }
    REQUIRE(fclose(f) == 0);
    test_brick_raw(raw, ibv, 8, 4);
    ip_error err;
    ip_store *s;
    ip_cache *c;
    REQUIRE(ip_store_open(ibv, &s, &err) == IP_OK);
    REQUIRE(ip_cache_create(s, 1u << 20, &c, &err) == IP_OK);
    uint64_t groups = 0, bad = 0, odd = 0;
    for (uint64_t g = 0; g < ip_store_layout(s)->brick_count; g++) {
        ip_brick b;
        REQUIRE(ip_cache_pin_brick(c, g, &b, &err) == IP_OK);
        const int16_t *v = b.samples, *r = b.group_ranges;
        const uint32_t *e = b.extent,
                       n[3] = {ip_cell_groups(e[0]), ip_cell_groups(e[1]), ip_cell_groups(e[2])};
        const uint32_t G = IP_CELL_GROUP;
        odd += (e[0] - 1) % G || (e[1] - 1) % G || (e[2] - 1) % G;
        for (uint32_t gz = 0; gz < n[2]; gz++)
            for (uint32_t gy = 0; gy < n[1]; gy++)
                for (uint32_t gx = 0; gx < n[0]; gx++) {
                    int least = INT16_MAX, most = INT16_MIN;
                    /* every corner of every cell of the group: cells G g .. G g + G - 1 where
                     * the brick has them (cells are samples 0 .. extent - 2) */
                    for (uint32_t cz = G * gz; cz < G * gz + G && cz + 1 < e[2]; cz++)
                        for (uint32_t cy = G * gy; cy < G * gy + G && cy + 1 < e[1]; cy++)
                            for (uint32_t cx = G * gx; cx < G * gx + G && cx + 1 < e[0]; cx++)
                                for (int k = 0; k < 8; k++) {
                                    int sample = v[cx + (k & 1) +
                                                   e[0] * (cy + ((k >> 1) & 1) +
                                                           e[1] * (cz + ((k >> 2) & 1)))];
                                    least = sample < least ? sample : least;
                                    most = sample > most ? sample : most;
                                }
                    size_t i = gx + n[0] * (gy + (size_t)n[1] * gz);
                    bad += r[2 * i] != least || r[2 * i + 1] != most;
                    groups++;
                }
        ip_cache_unpin_brick(c, &b);
    }
    CHECK_MSG(bad == 0, "%llu of %llu cell groups with a wrong range", (unsigned long long)bad,
              (unsigned long long)groups);
    CHECK_GT(odd, 0);
    CHECK_GT(groups, 0);
    ip_cache_destroy(c);
    ip_store_close(s);
}

/* ip__cache_pin_resident(): a pin of what is resident, never a read */
static void test_pin_resident(void)
{
    const ip_store *s = the_store;
    ip_cache *c;
    ip_cache_stats st;
    ip_brick b;
    REQUIRE(ip_cache_create(s, 8 * BRICK_BYTES, &c, NULL) == IP_OK);
    CHECK(!ip__cache_pin_resident(c, 3, &b)); /* not resident: nothing read, nothing touched */
    CHECK(!ip__cache_pin_resident(c, 1u << 30, &b)); /* no such brick */
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.misses, 0);
    CHECK_EQ(st.hits, 0);
    CHECK_EQ(st.resident_bytes, 0);
    CHECK_EQ(st.bricks_touched, 0);
    pin_unpin(c, 3);
    if (!CHECK(ip__cache_pin_resident(c, 3, &b))) { /* resident now: a hit on the same brick */
        ip_cache_destroy(c);
        return;
    }
    CHECK_EQ(b.index, 3);
    CHECK(brick_ok(&b));
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.misses, 1);
    CHECK_EQ(st.hits, 1);
    CHECK_EQ(st.pinned_bytes, BRICK_BYTES);
    ip_cache_unpin_brick(c, &b);
    ip_cache_get_stats(c, &st);
    CHECK_EQ(st.pinned_bytes, 0);
    ip_cache_destroy(c);
}

static const test_case cases[] = {
    TEST_CASE(test_scripted_lru), TEST_CASE(test_pinning),       TEST_CASE(test_pin_resident),
    TEST_CASE(test_threads),      TEST_CASE(test_corrupt_brick), TEST_CASE(test_group_ranges),
};

static void open_store(void)
{
    scratch_dir = test_tmp_dir("test_cache");
    make_file(scratch_dir, scratch_ibv, sizeof scratch_ibv);
    ip_error err;
    REQUIRE(ip_store_open(scratch_ibv, &the_store, &err) == IP_OK);
    REQUIRE(ip_store_layout(the_store)->levels[0].brick_count == 64);
}

static void close_store(void)
{
    ip_store_close(the_store);
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_cache", open_store, close_store);
}
