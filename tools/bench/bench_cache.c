/* SPDX-License-Identifier: BSD-3-Clause */
/* bench_cache: speed of the brick cache on one brick file, printed as Markdown tables.
 *
 * Three parts, each over the bricks of level 0:
 *   decode  throughput of a brick read (XXH64 + LZ4 + filters) beside its parts alone;
 *   hits    latency of pin + unpin of a resident brick, one thread and all threads;
 *   random / sequential   the cache under several budgets: hits, misses, evictions, time, memory.
 * A benchmark, not a test: every figure depends on the machine and on what else runs on it.
 */
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <lz4.h>
#include <xxhash.h>

#include "isoprop/cache.h"
#include "codec.h"
#include "isoprop/store.h"
#include "isoprop/system.h"
#include "tool_common.h"

static const char program[] = "bench_cache";

static const char usage[] =
    "usage: bench_cache FILE.ibv [--threads N] [--budgets LIST] [--only PARTS] [--quick]\n"
    "Measures the brick cache on the level-0 bricks of FILE.ibv; prints Markdown tables.\n"
    "  --threads N      threads of the parallel rows (default: all cores)\n"
    "  --budgets LIST   cache budgets in MiB for the random and sequential runs, comma-separated;\n"
    "                   'all' is the decoded size of level 0 rounded up, left out when another\n"
    "                   listed budget holds level 0 already (default 16,64,256,all)\n"
    "  --only PARTS     comma-separated subset of decode,hits,random,sequential (default all)\n"
    "  --quick          fewer and shorter repetitions, a random run of 1 x (not 4 x) the\n"
    "                   level-0 brick count: a smoke run, not figures to quote\n";

enum {
    PART_DECODE = 1,
    PART_HITS = 2,
    PART_RANDOM = 4,
    PART_SEQUENTIAL = 8
};

typedef struct options {
    const char *path;
    unsigned threads;
    const char *budgets;
    unsigned parts;
    int quick;
} options;

/* ---- small helpers: time, memory, statistics ---- */

/* Resets the process's peak RSS to its current RSS (Linux >= 4.0); 0 on success. */
static int reset_peak_rss(void)
{
    FILE *f = fopen("/proc/self/clear_refs", "w");
    if (!f)
        return -1;
    int ok = fputs("5", f) >= 0;
    return fclose(f) == 0 && ok ? 0 : -1;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorts v in place and returns its median. */
static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, compare_doubles);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static uint64_t splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Prints "bench_cache: out of memory for WHAT" and returns the exit code 1. */
static int out_of_memory(const char *what)
{
    fprintf(stderr, "%s: out of memory for %s\n", program, what);
    return 1;
}

static double mib(uint64_t bytes)
{
    return (double)bytes / 1048576.0;
}

/* ---- a team of threads started together, timed from the first start to the last finish ---- */

typedef struct team_member {
    void *(*work)(void *);
    void *arg;
    pthread_barrier_t *start;
    double started, finished;
} team_member;

/* Each thread reads the clock itself: on a busy machine the thread that released the barrier
 * may only run again after the others have finished. */
static void *team_entry(void *p)
{
    team_member *m = p;
    pthread_barrier_wait(m->start);
    m->started = ip_now_seconds();
    m->work(m->arg);
    m->finished = ip_now_seconds();
    return NULL;
}

/* Runs work(args + t * arg_size) on `threads` threads started at once; returns the wall
 * seconds from the first thread's start to the last one's finish, and when `each` is not NULL
 * fills each[t] with thread t's own seconds. Exits on failure (a benchmark has nothing
 * sensible to go on with). */
static double run_team(unsigned threads, void *(*work)(void *), void *args, size_t arg_size,
                       double *each)
{
    pthread_t *ids = calloc(threads, sizeof *ids);
    team_member *members = calloc(threads, sizeof *members);
    pthread_barrier_t start;
    if (!ids || !members) {
        fprintf(stderr, "%s: out of memory for %u threads\n", program, threads);
        exit(1);
    }
    pthread_barrier_init(&start, NULL, threads + 1);
    unsigned made = 0;
    for (; made < threads; made++) {
        members[made] = (team_member){work, (char *)args + made * arg_size, &start, 0, 0};
        if (pthread_create(&ids[made], NULL, team_entry, &members[made]) != 0)
            break;
    }
    if (made < threads) {
        fprintf(stderr, "%s: cannot start %u threads\n", program, threads);
        exit(1); /* the started threads wait at the barrier forever: nothing to clean up */
    }
    pthread_barrier_wait(&start);
    double t0 = 0, t1 = 0;
    for (unsigned t = 0; t < threads; t++) {
        pthread_join(ids[t], NULL);
        if (t == 0 || members[t].started < t0)
            t0 = members[t].started;
        if (t == 0 || members[t].finished > t1)
            t1 = members[t].finished;
        if (each)
            each[t] = members[t].finished - members[t].started;
    }
    pthread_barrier_destroy(&start);
    free(ids);
    free(members);
    return t1 - t0;
}

/* ---- the file: level-0 bricks and what they hold ---- */

typedef struct brick_info {
    uint64_t g;
    ip_brick_entry entry;
    uint32_t extent[3];
    uint64_t decoded_bytes;
    float constant_value;
} brick_info;

typedef struct bench_file {
    ip_store *store;
    const ip_layout *layout;
    unsigned char *payloads; /* the file up to its summary section, read once: the bytes
                                     the stages below other than ip_store_read_brick work on */
    size_t type_size;
    uint64_t level0_count;   /* every level-0 brick */
    uint64_t level0_decoded; /* their decoded bytes */
    brick_info *bricks;      /* every level-0 brick, in directory order */
    brick_info *payload;     /* the level-0 bricks with a payload (LZ4 or raw) */
    uint64_t payload_count;
    uint64_t counts[3]; /* level-0 bricks by encoding */
    uint64_t with_delta, with_med, with_shuffle;
    uint64_t largest_brick_bytes; /* decoded bytes of the largest brick */
    size_t work_size;
} bench_file;

/* Reads the file's header and data section into f->payloads (the store reads payloads itself,
 * into its callers' scratch; the stages that time the codec alone need the bytes in memory). */
static int read_payloads(const char *path, bench_file *f)
{
    uint64_t size = f->layout->summary_offset;
    f->payloads = malloc(size ? size : 1);
    if (!f->payloads)
        return out_of_memory("the payloads");
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    uint64_t done = 0;
    while (fd >= 0 && done < size) {
        ssize_t n = pread(fd, f->payloads + done, size - done, (off_t)done);
        if (n <= 0)
            break;
        done += (uint64_t)n;
    }
    if (fd >= 0)
        close(fd);
    if (done != size) {
        fprintf(stderr, "%s: %s: cannot read the data section\n", program, path);
        return 1;
    }
    return 0;
}

static int open_file(const char *path, bench_file *f)
{
    ip_error err;
    memset(f, 0, sizeof *f);
    if (ip_store_open(path, &f->store, &err) != IP_OK)
        return tool_fail(program, &err);
    f->layout = ip_store_layout(f->store);
    f->type_size = ip_type_size(f->layout->type);
    const ip_level_layout *lv = &f->layout->levels[0];
    f->level0_count = lv->brick_count;
    size_t n = lv->brick_count ? (size_t)lv->brick_count : 1;
    f->bricks = calloc(n, sizeof *f->bricks);
    f->payload = calloc(n, sizeof *f->payload);
    if (!f->bricks || !f->payload)
        return out_of_memory("the brick lists");
    for (uint64_t i = 0; i < lv->brick_count; i++) {
        uint64_t g = lv->first_brick + i;
        uint64_t bytes = ip_store_brick_samples(f->store, g) * f->type_size;
        f->level0_decoded += bytes;
        if (bytes > f->largest_brick_bytes)
            f->largest_brick_bytes = bytes;
        brick_info b = {.g = g, .decoded_bytes = bytes};
        ip_store_brick_entry(f->store, g, &b.entry);
        if (b.entry.encoding < 3)
            f->counts[b.entry.encoding]++;
        uint32_t level, coords[3], origin[3];
        ip_brick_coords(f->layout, g, &level, coords);
        ip_brick_extent(f->layout, level, coords, origin, b.extent);
        float range[2];
        ip_store_brick_range(f->store, g, range);
        b.constant_value = range[0];
        f->bricks[i] = b;
        if (b.entry.encoding == IP_BRICK_CONSTANT)
            continue;
        f->with_delta += (b.entry.filters & IP_FILTER_DELTA) != 0;
        f->with_med += (b.entry.filters & IP_FILTER_MED) != 0;
        f->with_shuffle += (b.entry.filters & IP_FILTER_SHUFFLE) != 0;
        f->payload[f->payload_count++] = b;
    }
    f->work_size = ip_store_read_work_size(f->store);
    return 0;
}

/* Reads the whole file once so that the page cache holds it. */
static int warm_page_cache(const char *path)
{
    int fd = open(path, O_RDONLY);
    if (fd < 0) {
        fprintf(stderr, "%s: %s: %s\n", program, path, strerror(errno));
        return 1;
    }
    static char buf[1 << 20];
    ssize_t n;
    while ((n = read(fd, buf, sizeof buf)) > 0)
        ;
    close(fd);
    return 0;
}

static void print_file_facts(const bench_file *f, const options *o)
{
    const ip_layout *l = f->layout;
    printf("## %s\n\n", ip_store_path(f->store));
    printf("- volume: %u x %u x %u %s, bricks of %u^3 cells, %u levels, %llu bricks in all\n",
           l->dims[0], l->dims[1], l->dims[2], ip_type_name(l->type), l->brick_edge, l->level_count,
           (unsigned long long)l->brick_count);
    printf("- level 0: %llu bricks (%llu constant, %llu LZ4, %llu raw), %.1f MiB decoded\n",
           (unsigned long long)f->level0_count, (unsigned long long)f->counts[IP_BRICK_CONSTANT],
           (unsigned long long)f->counts[IP_BRICK_LZ4], (unsigned long long)f->counts[IP_BRICK_RAW],
           mib(f->level0_decoded));
    printf("- level-0 LZ4 filters: %llu delta, %llu median edge, %llu byte shuffle\n",
           (unsigned long long)f->with_delta, (unsigned long long)f->with_med,
           (unsigned long long)f->with_shuffle);
    printf("- threads: %u of %ld online cores%s\n\n", o->threads, sysconf(_SC_NPROCESSORS_ONLN),
           o->quick ? "; --quick (smoke run: do not quote these figures)" : "");
}

/* ---- part 1: decode throughput ---- */

typedef enum stage {
    STAGE_READ,   /* ip_store_read_brick: XXH64 + LZ4 + filters */
    STAGE_DECODE, /* ip__codec_decode: LZ4 + filters */
    STAGE_LZ4,    /* LZ4_decompress_safe alone */
    STAGE_XXH64   /* XXH64 alone */
} stage;

static const char *const stage_names[] = {"ip_store_read_brick (XXH64 + LZ4 + filters)",
                                          "ip__codec_decode (LZ4 + filters)",
                                          "LZ4_decompress_safe alone", "XXH64 alone"};

typedef struct decode_job {
    const bench_file *file;
    const brick_info *list;
    uint64_t count;
    stage what;
    unsigned thread, threads;
    uint64_t passes;
    void *dst, *work;
    uint64_t sink; /* keeps the checksums alive */
    int failed;
} decode_job;

static void *decode_work(void *p)
{
    decode_job *j = p;
    const bench_file *f = j->file;
    ip_error err;
    for (uint64_t pass = 0; pass < j->passes; pass++)
        for (uint64_t i = j->thread; i < j->count; i += j->threads) {
            const brick_info *b = &j->list[i];
            const unsigned char *src = f->payloads + b->entry.offset;
            switch (j->what) {
            case STAGE_READ:
                j->failed |= ip_store_read_brick(f->store, b->g, j->dst, j->work, &err) != IP_OK;
                break;
            case STAGE_DECODE:
                j->failed |= ip__codec_decode(&b->entry, src, b->extent, f->layout->type,
                                              b->constant_value, j->dst, j->work) != IP_OK;
                break;
            case STAGE_LZ4:
                if (b->entry.encoding == IP_BRICK_LZ4)
                    j->failed |=
                        LZ4_decompress_safe((const char *)src, j->dst, (int)b->entry.stored_size,
                                            (int)b->decoded_bytes) != (int)b->decoded_bytes;
                break;
            case STAGE_XXH64: j->sink += XXH64(src, b->entry.stored_size, 0); break;
            }
        }
    return NULL;
}

/* Bytes one pass over `list` decodes (or, for XXH64, covers) and reads, and its bricks. */
static void stage_bytes(const brick_info *list, uint64_t count, stage what, uint64_t *decoded,
                        uint64_t *stored, uint64_t *bricks)
{
    *decoded = *stored = *bricks = 0;
    for (uint64_t i = 0; i < count; i++) {
        const brick_info *b = &list[i];
        if (what == STAGE_LZ4 && b->entry.encoding != IP_BRICK_LZ4)
            continue;
        *decoded += b->decoded_bytes;
        *stored += b->entry.stored_size;
        (*bricks)++;
    }
}

/* Times `passes` passes of a stage over `list` on `threads` threads; returns wall seconds. */
static double time_stage(const bench_file *f, const brick_info *list, uint64_t count, stage what,
                         unsigned threads, uint64_t passes, decode_job *jobs)
{
    for (unsigned t = 0; t < threads; t++) {
        jobs[t].file = f;
        jobs[t].list = list;
        jobs[t].count = count;
        jobs[t].what = what;
        jobs[t].thread = t;
        jobs[t].threads = threads;
        jobs[t].passes = passes;
    }
    return run_team(threads, decode_work, jobs, sizeof *jobs, NULL);
}

typedef struct rate {
    double median, best; /* decoded bytes per second per thread */
} rate;

/* Calibrates passes so that one timing lasts at least min_seconds (which also warms up), then
 * takes `samples` timings. Returns -1 after printing a message if a brick failed. */
static int measure_stage(const bench_file *f, const brick_info *list, uint64_t count, stage what,
                         unsigned threads, const options *o, decode_job *jobs, rate *out)
{
    const int samples = o->quick ? 3 : 5;
    const double min_seconds = o->quick ? 0.05 : 0.25;
    uint64_t decoded, stored, bricks;
    stage_bytes(list, count, what, &decoded, &stored, &bricks);
    uint64_t passes = 1;
    double t = time_stage(f, list, count, what, threads, passes, jobs);
    while (t < min_seconds) {
        double grow = min_seconds / (t > 1e-6 ? t : 1e-6) * 1.2; /* at most 10x a step */
        passes = (uint64_t)((double)passes * (grow < 2.0 ? 2.0 : grow > 10.0 ? 10.0 : grow));
        t = time_stage(f, list, count, what, threads, passes, jobs);
    }
    double rates[16];
    out->best = 0;
    for (int k = 0; k < samples; k++) {
        double secs = time_stage(f, list, count, what, threads, passes, jobs);
        rates[k] = (double)decoded * (double)passes / secs / threads;
        out->best = rates[k] > out->best ? rates[k] : out->best;
    }
    out->median = median(rates, (size_t)samples);
    for (unsigned u = 0; u < threads; u++)
        if (jobs[u].failed) {
            fprintf(stderr, "%s: %s: a brick failed to decode in stage '%s'\n", program,
                    ip_store_path(f->store), stage_names[what]);
            return -1;
        }
    return 0;
}

/* Label of a group of bricks by encoding and filters, e.g. "LZ4, median edge + shuffle". */
static const char *group_name(unsigned key, char *buf, size_t size)
{
    unsigned encoding = key >> 8, filters = key & 0xff;
    if (encoding == IP_BRICK_CONSTANT)
        return "constant (a fill, no payload)";
    if (encoding == IP_BRICK_RAW)
        return "raw (a copy)";
    snprintf(buf, size, "LZ4, %s%s%s", filters & IP_FILTER_DELTA ? "delta" : "",
             filters & IP_FILTER_MED ? "median edge" : "",
             filters & IP_FILTER_SHUFFLE ? (filters & 5u ? " + shuffle" : "shuffle")
                                         : (filters & 5u ? "" : "no filter"));
    return buf;
}

static int bench_decode_groups(const bench_file *f, const options *o, decode_job *jobs)
{
    brick_info *group = malloc(f->level0_count * sizeof *group);
    if (!group)
        return out_of_memory("a brick list");
    printf("By encoding and filters, one thread, all level-0 bricks (constant ones included, "
           "as a cache miss decodes them too): ip__codec_decode against LZ4 alone on the same "
           "bricks; \"filters\" is the share of ip__codec_decode's time spent outside LZ4.\n\n");
    printf("| bricks | count | decoded MiB | ip__codec_decode GB/s | LZ4 alone GB/s | "
           "us per brick | filters |\n");
    printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    for (unsigned key = 0; key < 0x400; key++) {
        uint64_t count = 0;
        for (uint64_t i = 0; i < f->level0_count; i++) {
            const brick_info *b = &f->bricks[i];
            if ((unsigned)(b->entry.encoding << 8 | b->entry.filters) == key)
                group[count++] = *b;
        }
        if (count == 0)
            continue;
        rate whole, lz4 = {0, 0};
        if (measure_stage(f, group, count, STAGE_DECODE, 1, o, jobs, &whole) != 0 ||
            ((key >> 8) == IP_BRICK_LZ4 &&
             measure_stage(f, group, count, STAGE_LZ4, 1, o, jobs, &lz4) != 0))
            return 1;
        uint64_t decoded, stored, bricks;
        stage_bytes(group, count, STAGE_DECODE, &decoded, &stored, &bricks);
        char name[64], lz4_text[32] = "-", share[32] = "-";
        if (lz4.median > 0) {
            snprintf(lz4_text, sizeof lz4_text, "%.2f", lz4.median / 1e9);
            snprintf(share, sizeof share, "%.0f %%", 100.0 * (1.0 - whole.median / lz4.median));
        }
        printf("| %s | %llu | %.1f | %.2f | %s | %.1f | %s |\n", group_name(key, name, sizeof name),
               (unsigned long long)count, mib(decoded), whole.median / 1e9, lz4_text,
               (double)decoded / whole.median / (double)count * 1e6, share);
    }
    printf("\n");
    free(group);
    return 0;
}

static int bench_decode(const bench_file *f, const options *o)
{
    printf("### Decode throughput, level-0 bricks, warm page cache\n\n");
    unsigned max_threads = o->threads;
    decode_job *jobs = calloc(max_threads, sizeof *jobs);
    if (!jobs)
        return out_of_memory("decode jobs");
    for (unsigned t = 0; t < max_threads; t++) {
        jobs[t].dst = malloc(f->largest_brick_bytes);
        jobs[t].work = malloc(f->work_size);
        if (!jobs[t].dst || !jobs[t].work)
            return out_of_memory("decode buffers");
    }
    printf("Each figure is the median of %d timings of at least %.2f s each (the best in "
           "brackets). GB/s per core = bytes / wall second / threads, 1 GB = 10^9 bytes. "
           "\"decoded\" counts the bricks' decoded bytes (for XXH64 alone, of the bricks it "
           "hashes, so that all rows compare per decoded byte), \"stored\" their payload bytes. "
           "Threads take interleaved disjoint shares of the bricks.\n\n",
           o->quick ? 3 : 5, o->quick ? 0.05 : 0.25);
    if (f->payload_count > 0) {
        printf("Level-0 bricks with a payload:\n\n");
        printf("| stage | threads | bricks | stored MiB | decoded MiB | decoded GB/s per core | "
               "stored GB/s per core | us per brick per core |\n");
        printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    } else
        printf("Every level-0 brick is constant: no payload to decode.\n\n");
    unsigned thread_counts[2] = {1, max_threads};
    int rows = max_threads > 1 ? 2 : 1;
    for (int s = STAGE_READ; s <= STAGE_XXH64 && f->payload_count > 0; s++) {
        uint64_t decoded, stored, bricks;
        stage_bytes(f->payload, f->payload_count, (stage)s, &decoded, &stored, &bricks);
        if (bricks == 0)
            continue;
        for (int r = 0; r < rows; r++) {
            rate m;
            if (measure_stage(f, f->payload, f->payload_count, (stage)s, thread_counts[r], o, jobs,
                              &m) != 0)
                return 1;
            printf("| %s | %u | %llu | %.1f | %.1f | %.2f (%.2f) | %.2f | %.1f |\n", stage_names[s],
                   thread_counts[r], (unsigned long long)bricks, mib(stored), mib(decoded),
                   m.median / 1e9, m.best / 1e9, m.median * (double)stored / (double)decoded / 1e9,
                   (double)decoded / m.median / (double)bricks * 1e6);
        }
    }
    if (f->payload_count > 0)
        printf("\n");
    int st = bench_decode_groups(f, o, jobs);
    for (unsigned t = 0; t < max_threads; t++) {
        free(jobs[t].dst);
        free(jobs[t].work);
    }
    free(jobs);
    return st;
}

/* ---- part 2: hit-path latency ---- */

typedef struct hit_job {
    ip_cache *cache;
    const uint64_t *bricks; /* the bricks this thread cycles through */
    uint64_t brick_count;
    uint64_t iterations;
    atomic_uint_fast64_t *shared_counter; /* reference runs only */
    int failed;
} hit_job;

static void *hit_work(void *p)
{
    hit_job *j = p;
    ip_error err;
    ip_brick b;
    uint64_t k = 0;
    for (uint64_t i = 0; i < j->iterations; i++) {
        if (ip_cache_pin_brick(j->cache, j->bricks[k], &b, &err) != IP_OK) {
            j->failed = 1;
            return NULL;
        }
        ip_cache_unpin_brick(j->cache, &b);
        if (++k == j->brick_count)
            k = 0;
    }
    return NULL;
}

static void *counter_work(void *p)
{
    hit_job *j = p;
    for (uint64_t i = 0; i < j->iterations; i++)
        atomic_fetch_add(j->shared_counter, 1);
    return NULL;
}

typedef struct hit_case {
    const char *name;
    unsigned threads;
    int same_brick; /* every thread on one brick */
    int cycle_all;  /* one thread through every level-0 brick in shuffled order */
    int reference;  /* shared atomic counter instead of the cache */
} hit_case;

static int bench_hits(const bench_file *f, const options *o)
{
    ip_error err;
    ip_cache *cache;
    uint64_t budget = f->level0_decoded + (64ull << 20);
    if (ip_cache_create(f->store, budget, &cache, &err) != IP_OK)
        return tool_fail(program, &err);
    uint64_t n = f->level0_count;
    uint64_t *order = malloc(n * sizeof *order);
    if (!order)
        return out_of_memory("a brick list");
    for (uint64_t i = 0; i < n; i++) {
        ip_brick b;
        order[i] = f->layout->levels[0].first_brick + i;
        if (ip_cache_pin_brick(cache, order[i], &b, &err) != IP_OK)
            return tool_fail(program, &err);
        ip_cache_unpin_brick(cache, &b);
    }
    uint64_t seed = 42;
    for (uint64_t i = n; i > 1; i--) {
        uint64_t k = splitmix64(&seed) % i;
        uint64_t tmp = order[i - 1];
        order[i - 1] = order[k];
        order[k] = tmp;
    }
    unsigned threads = o->threads;
    hit_case cases[6];
    int case_count = 0;
    cases[case_count++] = (hit_case){"one brick", 1, 1, 0, 0};
    cases[case_count++] = (hit_case){"every level-0 brick, shuffled", 1, 0, 1, 0};
    if (threads > 1) {
        cases[case_count++] = (hit_case){"a different brick per thread", threads, 0, 0, 0};
        cases[case_count++] = (hit_case){"the same brick on every thread", threads, 1, 0, 0};
        cases[case_count++] =
            (hit_case){"reference: atomic_fetch_add on one shared counter", threads, 0, 0, 1};
    }
    const uint64_t iterations = o->quick ? 200000 : 2000000;
    const int runs = o->quick ? 3 : 7;
    printf("### Hit path: pin + unpin of a resident brick\n\n");
    printf(
        "Every level-0 brick is resident (budget %.0f MiB). Each thread does %llu pin + "
        "unpin pairs per run; ns per pair is a thread's own time / its pairs (the latency a "
        "caller sees), averaged over the threads, the median of %d runs (fastest and slowest "
        "in brackets); pairs per second counts all threads over the run's wall time (median).\n\n",
        mib(budget), (unsigned long long)iterations, runs);
    printf("| case | threads | ns per pair | million pairs per second, all threads |\n");
    printf("| --- | ---: | ---: | ---: |\n");
    hit_job *jobs = calloc(threads, sizeof *jobs);
    uint64_t *own = calloc(threads, sizeof *own);
    double *each = calloc(threads, sizeof *each);
    atomic_uint_fast64_t counter;
    atomic_init(&counter, 0);
    if (!jobs || !own || !each)
        return out_of_memory("hit jobs");
    for (int c = 0; c < case_count; c++) {
        const hit_case *hc = &cases[c];
        for (unsigned t = 0; t < hc->threads; t++) {
            /* different bricks lie far apart in the directory, so on distinct cache lines */
            own[t] = hc->same_brick ? order[0] : order[(uint64_t)t * n / hc->threads];
            jobs[t] = (hit_job){
                cache, hc->cycle_all ? order : &own[t], hc->cycle_all ? n : 1, iterations, &counter,
                0};
        }
        double ns[16], rates[16];
        for (int r = 0; r < runs; r++) {
            double wall = run_team(hc->threads, hc->reference ? counter_work : hit_work, jobs,
                                   sizeof *jobs, each);
            double sum = 0;
            for (unsigned t = 0; t < hc->threads; t++)
                sum += each[t];
            ns[r] = sum / hc->threads * 1e9 / (double)iterations;
            rates[r] = (double)hc->threads * (double)iterations / wall;
        }
        for (unsigned t = 0; t < hc->threads; t++)
            if (jobs[t].failed) {
                fprintf(stderr, "%s: %s: a resident brick failed to pin\n", program,
                        ip_store_path(f->store));
                return 1;
            }
        double med = median(ns, (size_t)runs);
        printf("| %s | %u | %.1f (%.1f .. %.1f) | %.1f |\n", hc->name, hc->threads, med, ns[0],
               ns[runs - 1], median(rates, (size_t)runs) / 1e6);
    }
    printf("\n");
    ip_cache_stats s;
    ip_cache_get_stats(cache, &s);
    if (s.misses != f->level0_count || s.evictions != 0)
        printf("Note: the hit runs saw %llu misses and %llu evictions (expected %llu and 0).\n\n",
               (unsigned long long)s.misses, (unsigned long long)s.evictions,
               (unsigned long long)f->level0_count);
    ip_cache_destroy(cache);
    free(jobs);
    free(own);
    free(each);
    free(order);
    return 0;
}

/* ---- parts 3 and 4: random and sequential runs under a budget ---- */

typedef struct run_job {
    ip_cache *cache;
    const uint64_t *sequence;
    uint64_t count;
    unsigned thread, threads;
    int failed;
    ip_error err;
} run_job;

static void *run_work(void *p)
{
    run_job *j = p;
    ip_brick b;
    for (uint64_t i = j->thread; i < j->count; i += j->threads) {
        if (ip_cache_pin_brick(j->cache, j->sequence[i], &b, &j->err) != IP_OK) {
            j->failed = 1;
            return NULL;
        }
        ip_cache_unpin_brick(j->cache, &b);
    }
    return NULL;
}

typedef struct budget_list {
    uint64_t mib[32];
    int count;
    int all_index; /* which entry is 'all', or -1 */
} budget_list;

static int parse_budgets(const char *text, const bench_file *f, budget_list *out)
{
    char buf[512];
    char *save = NULL;
    if (strlen(text) >= sizeof buf)
        return -1;
    strcpy(buf, text);
    out->count = 0;
    out->all_index = -1;
    uint64_t all = (f->level0_decoded + (1u << 20) - 1) / (1u << 20) + 1;
    int covered = 0;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        uint64_t v;
        if (out->count == 32)
            return -1;
        if (strcmp(tok, "all") == 0) {
            out->all_index = out->count;
            v = all;
        } else if (tool_parse_u64(tok, &v) != 0 || v < 1 || v > (1ull << 30))
            return -1;
        else
            covered |= (v << 20) >= f->level0_decoded;
        out->mib[out->count++] = v;
    }
    if (out->count == 0)
        return -1;
    if (out->all_index >= 0 && covered) { /* a listed budget already holds level 0 */
        for (int i = out->all_index; i + 1 < out->count; i++)
            out->mib[i] = out->mib[i + 1];
        out->count--;
        out->all_index = -1;
    }
    return 0;
}

static int run_budget(const bench_file *f, const char *name, const uint64_t *sequence,
                      uint64_t count, uint64_t budget_mib, unsigned threads, int peak_resets)
{
    ip_error err;
    ip_cache *cache;
#ifdef __GLIBC__
    malloc_trim(0); /* give the previous run's bricks back, so RSS starts low */
#endif
    if (peak_resets)
        reset_peak_rss();
    uint64_t rss_before = ip_rss_bytes();
    if (ip_cache_create(f->store, budget_mib << 20, &cache, &err) != IP_OK)
        return tool_fail(program, &err);
    run_job *jobs = calloc(threads, sizeof *jobs);
    if (!jobs)
        return out_of_memory("run jobs");
    for (unsigned t = 0; t < threads; t++)
        jobs[t] = (run_job){cache, sequence, count, t, threads, 0, {IP_OK, {0}}};
    double secs = run_team(threads, run_work, jobs, sizeof *jobs, NULL);
    for (unsigned t = 0; t < threads; t++)
        if (jobs[t].failed)
            return tool_fail(program, &jobs[t].err);
    ip_cache_stats s;
    ip_cache_get_stats(cache, &s);
    uint64_t peak = ip_peak_rss_bytes();
    double all = (double)(s.hits + s.misses);
    double other_us = s.misses ? (secs * threads - s.decode_seconds) / (double)s.misses * 1e6 : 0;
    printf("| %s | %llu | %u | %llu | %llu | %llu | %llu | %.1f %% | %.2f | %.2f | %.2f | %.1f | "
           "%.0f | %.1f | %.0f | %.0f |\n",
           name, (unsigned long long)budget_mib, threads, (unsigned long long)count,
           (unsigned long long)s.hits, (unsigned long long)s.misses,
           (unsigned long long)s.evictions, all > 0 ? 100.0 * (double)s.hits / all : 0.0,
           (double)s.bytes_decompressed / 1e9, s.decode_seconds, secs, other_us,
           (double)count / secs, mib(s.resident_peak_bytes), mib(rss_before), mib(peak));
    fflush(stdout);
    ip_cache_destroy(cache);
    free(jobs);
    return 0;
}

static int bench_runs(const bench_file *f, const options *o, const budget_list *budgets)
{
    uint64_t n = f->level0_count, first = f->layout->levels[0].first_brick;
    uint64_t random_count = (o->quick ? 1 : 4) * n;
    uint64_t *random = malloc(random_count * sizeof *random);
    uint64_t *sweep = malloc(2 * n * sizeof *sweep);
    if (!random || !sweep)
        return out_of_memory("the pin sequences");
    uint64_t seed = 20240601;
    for (uint64_t i = 0; i < random_count; i++)
        random[i] = first + splitmix64(&seed) % n;
    for (uint64_t i = 0; i < 2 * n; i++)
        sweep[i] = first + i % n;
    int peak_resets = reset_peak_rss() == 0;
    printf("### Cache runs under a budget\n\n");
    printf("- random: %llu pins (%s x the %llu level-0 bricks), uniform, fixed seed; with N "
           "threads, thread t takes pins t, t + N, ... of the same sequence.\n",
           (unsigned long long)random_count, o->quick ? "1" : "4", (unsigned long long)n);
    printf("- sequential: every level-0 brick in directory order (x fastest), twice: %llu pins, "
           "one thread.\n",
           (unsigned long long)(2 * n));
    printf("- Each pin is followed by its unpin; nothing reads the samples. Level 0 decodes to "
           "%.1f MiB; budgets that hold all of it:",
           mib(f->level0_decoded));
    int holding = 0;
    for (int b = 0; b < budgets->count; b++)
        if ((budgets->mib[b] << 20) >= f->level0_decoded)
            printf("%s %llu MiB", holding++ ? "," : "", (unsigned long long)budgets->mib[b]);
    printf("%s.\n", holding ? "" : " none");
    printf(
        "- decode s: time inside checksum + decode summed over threads "
        "(ip_cache_stats.decode_seconds); other us per miss: (wall x threads - decode s) / "
        "misses, i.e. everything else a miss costs (victim scan, allocation, locks, the payload's read) "
        "plus the hits' share.\n");
    if (peak_resets)
        printf("- peak RSS is the process's high-water mark during the run alone: it is reset "
               "before each run (/proc/self/clear_refs), after the previous cache is freed "
               "and malloc_trim(); RSS before is the process at the start of the run (store "
               "summaries, sequences, allocator).\n\n");
    else
        printf("- peak RSS is the process's high-water mark since it started (it only grows: "
               "this kernel does not let it be reset), so only its first rise is this run's.\n\n");
    printf("| run | budget MiB | threads | pins | hits | misses | evictions | hit rate | decoded "
           "GB | decode s | wall s | other us per miss | pins per second | resident peak MiB | "
           "RSS before MiB | peak RSS MiB |\n");
    printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | "
           "---: | ---: | ---: | ---: |\n");
    for (int b = 0; b < budgets->count; b++) {
        uint64_t budget = budgets->mib[b];
        if (o->parts & PART_RANDOM) {
            if (run_budget(f, "random", random, random_count, budget, 1, peak_resets))
                return 1;
            if (o->threads > 1 &&
                run_budget(f, "random", random, random_count, budget, o->threads, peak_resets))
                return 1;
        }
        if ((o->parts & PART_SEQUENTIAL) &&
            run_budget(f, "sequential", sweep, 2 * n, budget, 1, peak_resets))
            return 1;
    }
    printf("\n");
    free(random);
    free(sweep);
    return 0;
}

/* ---- options ---- */

static int parse_parts(const char *text, unsigned *parts)
{
    char buf[128];
    char *save = NULL;
    if (strlen(text) >= sizeof buf)
        return -1;
    strcpy(buf, text);
    *parts = 0;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (strcmp(tok, "decode") == 0)
            *parts |= PART_DECODE;
        else if (strcmp(tok, "hits") == 0)
            *parts |= PART_HITS;
        else if (strcmp(tok, "random") == 0)
            *parts |= PART_RANDOM;
        else if (strcmp(tok, "sequential") == 0)
            *parts |= PART_SEQUENTIAL;
        else
            return -1;
    }
    return *parts ? 0 : -1;
}

static int parse_options(int argc, char **argv, options *o, int *exit_code)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    *o = (options){NULL, cores > 0 ? (unsigned)cores : 1, "16,64,256,all",
                   PART_DECODE | PART_HITS | PART_RANDOM | PART_SEQUENTIAL, 0};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            *exit_code = 0;
            return -1;
        }
        if (strcmp(a, "--quick") == 0) {
            o->quick = 1;
            continue;
        }
        if (strcmp(a, "--threads") == 0 || strcmp(a, "--budgets") == 0 ||
            strcmp(a, "--only") == 0) {
            if (i + 1 >= argc) {
                *exit_code = tool_usage_error(program, "%s needs a value", a);
                return -1;
            }
            const char *v = argv[++i];
            uint64_t n;
            if (strcmp(a, "--threads") == 0) {
                if (tool_parse_u64(v, &n) != 0 || n < 1 || n > 256) {
                    *exit_code = tool_usage_error(program, "--threads wants 1..256, not '%s'", v);
                    return -1;
                }
                o->threads = (unsigned)n;
            } else if (strcmp(a, "--budgets") == 0)
                o->budgets = v;
            else if (parse_parts(v, &o->parts) != 0) {
                *exit_code = tool_usage_error(
                    program, "--only wants decode, hits, random or sequential, not '%s'", v);
                return -1;
            }
            continue;
        }
        if (a[0] == '-' || o->path) {
            *exit_code = tool_usage_error(program, "unexpected argument '%s'", a);
            return -1;
        }
        o->path = a;
    }
    if (!o->path) {
        *exit_code = tool_usage_error(program, "no brick file given");
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    options o;
    int code;
    if (parse_options(argc, argv, &o, &code) != 0)
        return code;
    bench_file f;
    if (open_file(o.path, &f) != 0)
        return 1;
    budget_list budgets;
    if (parse_budgets(o.budgets, &f, &budgets) != 0)
        return tool_usage_error(program, "--budgets wants MiB values (1..2^30) or 'all', not '%s'",
                                o.budgets);
    if (warm_page_cache(o.path) != 0)
        return 1;
    print_file_facts(&f, &o);
    if ((o.parts & PART_DECODE) && (read_payloads(o.path, &f) != 0 || bench_decode(&f, &o) != 0))
        return 1;
    free(f.payloads); /* the runs below measure memory: only the store's own reads count */
    f.payloads = NULL;
    if ((o.parts & PART_HITS) && bench_hits(&f, &o) != 0)
        return 1;
    if ((o.parts & (PART_RANDOM | PART_SEQUENTIAL)) && bench_runs(&f, &o, &budgets) != 0)
        return 1;
    free(f.bricks);
    free(f.payload);
    ip_store_close(f.store);
    return 0;
}
