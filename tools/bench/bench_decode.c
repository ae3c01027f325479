/* SPDX-License-Identifier: BSD-3-Clause */
/* bench_decode: how fast one thread reads bricks, and where the time goes.
 *
 * Reads every level-0 brick with a payload (or of every level, --all-levels; constant bricks
 * too, --constant) of a brick file with ip_store_read_brick() on one thread, the page cache warm, and prints the best of N passes
 * in GB/s of decoded samples. The time split comes from the same passes built up one step at
 * a time, each step doing what ip_store_read_brick() does up to it, in the same scratch:
 *   pread       the payload into the scratch;
 *   + XXH64     then its checksum;
 *   + LZ4       then LZ4_decompress_safe() into the codec's scratch;
 *   + filters   then ip__codec_decode() instead of LZ4 alone (LZ4 + unshuffle + predictor).
 * A step's cost is its pass time minus the previous step's. The rows of a round run one after
 * the other, so that noise on this machine hits them alike.
 * A benchmark, not a test: every figure depends on the machine and on what else runs on it.
 */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <lz4.h>

#include "codec.h"
#include "format.h"
#include "isoprop/store.h"
#include "tool_common.h"

static const char program[] = "bench_decode";

static const char usage[] =
    "usage: bench_decode FILE.ibv [--passes N] [--all-levels] [--constant] [--only STEP]\n"
    "Reads the level-0 bricks with a payload of FILE.ibv on one thread; prints the best of N\n"
    "passes (GB/s of decoded samples) and the time split pread / XXH64 / LZ4 / filters as a\n"
    "Markdown table.\n"
    "  --passes N     passes per row (default 30)\n"
    "  --all-levels   the bricks of every level, not only level 0\n"
    "  --constant     constant bricks too (a fill, no payload)\n"
    "  --only STEP    run only one row, for a profiler: read, pread, xxh64, lz4 or decode\n";

/* The rows: the cumulative steps, then the whole ip_store_read_brick(). */
enum {
    STEP_PREAD,
    STEP_XXH64,
    STEP_LZ4,
    STEP_DECODE,
    STEP_READ,
    STEP_COUNT
};

static const char *const step_names[STEP_COUNT] = {"pread", "xxh64", "lz4", "decode", "read"};
static const char *const step_rows[STEP_COUNT] = {"pread", "pread + XXH64", "pread + XXH64 + LZ4",
                                                  "pread + XXH64 + ip__codec_decode",
                                                  "ip_store_read_brick"};

typedef struct brick {
    uint64_t g;
    ip_brick_entry entry;
    uint32_t extent[3];
    float constant_value;
    size_t bytes; /* decoded */
} brick;

typedef struct bench {
    ip_store *store;
    const ip_layout *layout;
    int fd;
    brick *bricks; /* the bricks read, in directory order */
    size_t count, with_payload, delta, med;
    uint64_t decoded, decoded_payload, stored;
    unsigned char *dst, *work;
    size_t work_size, payload_room; /* the scratch, and its part ahead of the codec's */
} bench;

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Records brick g, its entry and extent. */
static void add_brick(bench *b, uint64_t g)
{
    brick *k = &b->bricks[b->count++];
    uint32_t level, coords[3], origin[3];
    float range[2];
    k->g = g;
    ip_store_brick_entry(b->store, g, &k->entry);
    ip_brick_coords(b->layout, g, &level, coords);
    ip_brick_extent(b->layout, level, coords, origin, k->extent);
    ip_store_brick_range(b->store, g, range);
    k->constant_value = range[0];
    k->bytes = (size_t)ip_store_brick_samples(b->store, g) * ip_type_size(b->layout->type);
    b->decoded += k->bytes;
    if (k->entry.stored_size == 0)
        return;
    b->with_payload++;
    b->decoded_payload += k->bytes;
    b->stored += k->entry.stored_size;
    b->delta += (k->entry.filters & IP_FILTER_DELTA) != 0;
    b->med += (k->entry.filters & IP_FILTER_MED) != 0;
}

/* Opens the file, lists its bricks and allocates the destination and scratch. */
static int open_bench(const char *path, int all_levels, int constant, bench *b)
{
    ip_error err;
    memset(b, 0, sizeof *b);
    b->fd = -1;
    if (ip_store_open(path, &b->store, &err) != IP_OK)
        return tool_fail(program, &err);
    b->layout = ip_store_layout(b->store);
    uint64_t n = all_levels ? b->layout->brick_count : b->layout->levels[0].brick_count;
    size_t edge = (size_t)b->layout->brick_edge + 1;
    b->bricks = calloc(n ? n : 1, sizeof *b->bricks);
    b->work_size = ip_store_read_work_size(b->store);
    b->payload_room = b->work_size - ip__codec_work_size(edge * edge * edge, b->layout->type);
    b->work = malloc(b->work_size);
    b->dst = malloc(edge * edge * edge * ip_type_size(b->layout->type));
    b->fd = open(path, O_RDONLY | O_CLOEXEC);
    if (!b->bricks || !b->work || !b->dst || b->fd < 0) {
        fprintf(stderr, "%s: %s: out of memory or cannot open\n", program, path);
        return 1;
    }
    for (uint64_t g = b->layout->levels[0].first_brick; g < b->layout->levels[0].first_brick + n;
         g++) {
        ip_brick_entry e;
        ip_store_brick_entry(b->store, g, &e);
        if (e.stored_size > 0 || constant)
            add_brick(b, g);
    }
    return 0;
}

static void close_bench(bench *b)
{
    if (b->fd >= 0)
        close(b->fd);
    free(b->bricks);
    free(b->work);
    free(b->dst);
    ip_store_close(b->store);
}

/* One brick through the steps up to `step` (STEP_PREAD .. STEP_DECODE), as
 * ip_store_read_brick() does them; 0 on success. */
static int run_steps(bench *b, const brick *k, int step)
{
    const ip_brick_entry *e = &k->entry;
    unsigned char *payload = b->work, *scratch = b->work + b->payload_room;
    if (e->stored_size > 0) {
        if (pread(b->fd, payload, e->stored_size, (off_t)e->offset) != (ssize_t)e->stored_size)
            return 1;
        if (step >= STEP_XXH64 && ip__format_checksum(payload, e->stored_size) != e->checksum)
            return 1;
    }
    if (step == STEP_LZ4 && e->encoding == IP_BRICK_LZ4)
        return LZ4_decompress_safe((const char *)payload, (char *)scratch, (int)e->stored_size,
                                   (int)k->bytes) != (int)k->bytes;
    if (step == STEP_DECODE)
        return ip__codec_decode(e, payload, k->extent, b->layout->type, k->constant_value, b->dst,
                                scratch) != IP_OK;
    return 0;
}

/* Seconds of one pass of `step` over every brick; negative when a brick failed. */
static double pass(bench *b, int step)
{
    ip_error err;
    int failed = 0;
    double t0 = now();
    for (size_t i = 0; i < b->count; i++) {
        if (step == STEP_READ)
            failed |= ip_store_read_brick(b->store, b->bricks[i].g, b->dst, b->work, &err) != IP_OK;
        else
            failed |= run_steps(b, &b->bricks[i], step);
    }
    double t = now() - t0;
    return failed ? -1.0 : t;
}

static void print_facts(const bench *b, const char *path, int passes)
{
    const ip_layout *l = b->layout;
    printf("## %s\n\n", path);
    printf("- volume: %u x %u x %u %s, bricks of %u^3 cells\n", l->dims[0], l->dims[1], l->dims[2],
           ip_type_name(l->type), l->brick_edge);
    printf("- bricks read: %zu (%zu with a payload: %zu delta, %zu median edge), %.1f MiB "
           "decoded (%.1f MiB of them from payloads), %.1f MiB stored\n",
           b->count, b->with_payload, b->delta, b->med, (double)b->decoded / 1048576.0,
           (double)b->decoded_payload / 1048576.0, (double)b->stored / 1048576.0);
    printf("- one thread, best of %d passes, page cache warm; GB/s = decoded bytes of all the "
           "bricks read / pass seconds, 1 GB = 10^9 bytes\n\n",
           passes);
}

/* Prints the table: each row's best pass and its share; the steps' differences. */
static void print_table(const bench *b, const double best[STEP_COUNT], int only)
{
    printf("| row | ms per pass | decoded GB/s | this step alone, ms | share of "
           "ip_store_read_brick |\n");
    printf("| --- | ---: | ---: | ---: | ---: |\n");
    for (int s = 0; s < STEP_COUNT; s++) {
        if (only >= 0 && s != only)
            continue;
        double step =
            s == STEP_PREAD || s == STEP_READ || only >= 0 ? best[s] : best[s] - best[s - 1];
        if (s == STEP_DECODE && only < 0) /* decode replaces LZ4 alone: filters = its extra */
            step = best[STEP_DECODE] - best[STEP_LZ4];
        printf("| %s | %.2f | %.2f | %.2f | %.0f %% |\n", step_rows[s], best[s] * 1e3,
               (double)b->decoded / best[s] / 1e9, step * 1e3,
               only < 0 ? 100.0 * step / best[STEP_READ] : 100.0);
    }
    if (only < 0)
        printf("\nSteps: pread, XXH64 (second row minus first), LZ4 (third minus second), "
               "filters (fourth minus third); the rest of ip_store_read_brick is its fifth row "
               "minus the fourth: %.2f ms.\n",
               (best[STEP_READ] - best[STEP_DECODE]) * 1e3);
}

/* Parses the options; returns -1 to go on, else the exit code. */
static int parse(int argc, char **argv, const char **path, int *passes, int flags[2], int *only)
{
    for (int i = 1; i < argc; i++) {
        uint64_t v;
        if (!strcmp(argv[i], "--passes") && i + 1 < argc && !tool_parse_u64(argv[i + 1], &v) &&
            v > 0 && v < 100000) {
            *passes = (int)v;
            i++;
        } else if (!strcmp(argv[i], "--all-levels")) {
            flags[0] = 1;
        } else if (!strcmp(argv[i], "--constant")) {
            flags[1] = 1;
        } else if (!strcmp(argv[i], "--only") && i + 1 < argc) {
            for (*only = 0; *only < STEP_COUNT && strcmp(argv[i + 1], step_names[*only]); ++*only)
                ;
            if (*only == STEP_COUNT)
                return tool_usage_error(program, "unknown step '%s'", argv[i + 1]);
            i++;
        } else if (argv[i][0] != '-' && !*path) {
            *path = argv[i];
        } else {
            fputs(usage, stderr);
            return 2;
        }
    }
    if (!*path) {
        fputs(usage, stderr);
        return 2;
    }
    return -1;
}

int main(int argc, char **argv)
{
    const char *path = NULL;
    int passes = 30, flags[2] = {0, 0}, only = -1; /* --all-levels, --constant */
    int rc = parse(argc, argv, &path, &passes, flags, &only);
    if (rc >= 0)
        return rc;
    bench b;
    if (open_bench(path, flags[0], flags[1], &b) != 0) {
        close_bench(&b);
        return 1;
    }
    double best[STEP_COUNT];
    for (int s = 0; s < STEP_COUNT; s++)
        best[s] = 1e30;
    for (int p = 0; p <= passes && rc < 0; p++) /* pass 0 warms the page cache, untimed */
        for (int s = 0; s < STEP_COUNT && rc < 0; s++) {
            if (only >= 0 && s != only)
                continue;
            double t = pass(&b, s);
            if (t < 0) {
                fprintf(stderr, "%s: %s: a brick failed in row '%s'\n", program, path,
                        step_rows[s]);
                rc = 1;
            } else if (p > 0 && t < best[s]) {
                best[s] = t;
            }
        }
    if (rc < 0) {
        print_facts(&b, path, passes);
        print_table(&b, best, only);
        rc = 0;
    }
    close_bench(&b);
    return rc;
}
