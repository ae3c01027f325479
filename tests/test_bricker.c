/* SPDX-License-Identifier: BSD-3-Clause */
/* Bricking round trips: every sample of every brick of every level, and every summary,
 * recomputed from the raw input; plus determinism, cancellation and memory limits. */
#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "isoprop/bricker.h"
#include "codec.h"
#include "isoprop/generate.h"
#include "isoprop/input.h"
#include "isoprop/store.h"

/* A test volume: samples as floats, plus the raw bytes written to disk. */
typedef struct volume {
    uint32_t dims[3];
    ip_type type;
    float *values;
} volume;

static float sample_at(const volume *v, uint32_t x, uint32_t y, uint32_t z)
{
    return v->values[x + (size_t)v->dims[0] * (y + (size_t)v->dims[1] * z)];
}

/* What make_volume() fills a volume with: the pattern below, one value, or noise_at(). */
enum {
    FILL_PATTERN,
    FILL_CONSTANT,
    FILL_NOISE
};

/* Noise over the type's whole range (its extremes included in a volume of a few hundred
 * thousand 16-bit samples), so that every sub-block has a range of its own and a reduction in
 * the wrong order or sign shows in the summaries. */
static float noise_at(uint32_t x, uint32_t y, uint32_t z, ip_type type)
{
    uint32_t h = (x * 73856093u) ^ (y * 19349663u) ^ (z * 83492791u);
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    switch (type) {
    case IP_UINT8: return (float)(h & 0xffu);
    case IP_UINT16: return (float)(h & 0xffffu);
    case IP_INT16: return (float)((int32_t)(h & 0xffffu) - 32768);
    case IP_FLOAT32: return (float)((int32_t)(h & 0xfffffu) - 524288) * 0.25f;
    }
    return 0.0f;
}

/* Smooth structure, flat regions and noise, representable exactly in every type. */
static float pattern(uint32_t x, uint32_t y, uint32_t z, ip_type type, int fill)
{
    if (fill == FILL_CONSTANT)
        return type == IP_INT16 ? -77.0f : 77.0f;
    if (fill == FILL_NOISE)
        return noise_at(x, y, z, type);
    double r = sqrt((double)(x * x + y * y + z * z));
    double v = 100.0 + 90.0 * sin(r * 0.31) * cos(z * 0.17);
    if (x > 20 && y > 20)
        v = 3.0; /* a flat region: constant bricks */
    v += (double)((x * 7919u + y * 104729u + z * 1299709u) % 5u);
    if (type == IP_INT16)
        v -= 150.0;
    if (type == IP_UINT16)
        v *= 250.0;
    if (type == IP_FLOAT32)
        return (float)(v * 0.01);
    return (float)floor(v);
}

static void write_value(void *dst, size_t i, ip_type type, float v)
{
    switch (type) {
    case IP_UINT8: ((uint8_t *)dst)[i] = (uint8_t)v; break;
    case IP_UINT16: ((uint16_t *)dst)[i] = (uint16_t)v; break;
    case IP_INT16: ((int16_t *)dst)[i] = (int16_t)v; break;
    case IP_FLOAT32: ((float *)dst)[i] = v; break;
    }
}

static const char *scratch_dir; /* this program's scratch folder (setup) */

static volume make_volume(const char *dir, const uint32_t dims[3], ip_type type, int fill,
                          char *path, size_t path_size)
{
    volume v = {{dims[0], dims[1], dims[2]}, type, NULL};
    size_t n = (size_t)dims[0] * dims[1] * dims[2];
    v.values = malloc(n * sizeof(float));
    unsigned char *raw = malloc(n * ip_type_size(type));
    REQUIRE(v.values && raw);
    for (uint32_t z = 0, i = 0; z < dims[2]; z++)
        for (uint32_t y = 0; y < dims[1]; y++)
            for (uint32_t x = 0; x < dims[0]; x++, i++) {
                v.values[i] = pattern(x, y, z, type, fill);
                write_value(raw, i, type, v.values[i]);
            }
    char name[256];
    const char *stem = fill == FILL_CONSTANT ? "flat" : fill == FILL_NOISE ? "noise" : "vol";
    REQUIRE(ip_raw_file_name(name, sizeof name, stem, dims, type) == IP_OK);
    snprintf(path, path_size, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    REQUIRE(f && fwrite(raw, ip_type_size(type), n, f) == n && fclose(f) == 0);
    free(raw);
    return v;
}

/* Independent min/max of the inclusive box [lo, hi] of a brick of `extent` floats. */
static void box_range(const float *v, const uint32_t extent[3], const uint32_t lo[3],
                      const uint32_t hi[3], float *min, float *max)
{
    *min = INFINITY;
    *max = -INFINITY;
    for (uint32_t z = lo[2]; z <= hi[2]; z++)
        for (uint32_t y = lo[1]; y <= hi[1]; y++)
            for (uint32_t x = lo[0]; x <= hi[0]; x++) {
                float s = v[x + (size_t)extent[0] * (y + (size_t)extent[1] * z)];
                *min = fminf(*min, s);
                *max = fmaxf(*max, s);
            }
}

/* Checks every brick of every level against the source, and every summary. */
static void check_file(const char *ibv, const volume *v)
{
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open(ibv, &s, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    size_t most = (size_t)(l->brick_edge + 1) * (l->brick_edge + 1) * (l->brick_edge + 1);
    float *dst = malloc(most * 4);
    void *work = malloc(ip_store_read_work_size(s));
    float *sub = malloc(sizeof(float) * 2 * ip_layout_subblocks_per_brick(l));
    float *want = malloc(most * sizeof(float));
    REQUIRE(dst && work && sub && want);
    CHECK_EQ(l->type, v->type);
    CHECK_EQ(l->dims[0], v->dims[0]);
    CHECK_EQ(l->dims[2], v->dims[2]);
    CHECK_EQ(l->levels[l->level_count - 1].brick_count, 1);
    int sample_errors = 0, range_errors = 0;
    for (uint64_t g = 0; g < l->brick_count; g++) {
        uint32_t level, brick[3], origin[3], extent[3];
        ip_brick_coords(l, g, &level, brick);
        ip_brick_extent(l, level, brick, origin, extent);
        CHECK_EQ(ip_store_read_brick(s, g, dst, work, &err), IP_OK);
        uint32_t per = l->brick_edge / l->subblock_edge;
        for (uint32_t z = 0; z < extent[2]; z++)
            for (uint32_t y = 0; y < extent[1]; y++)
                for (uint32_t x = 0; x < extent[0]; x++) {
                    size_t i = x + (size_t)extent[0] * (y + (size_t)extent[1] * z);
                    want[i] = sample_at(v, ip_level_sample_index(v->dims[0], level, origin[0] + x),
                                        ip_level_sample_index(v->dims[1], level, origin[1] + y),
                                        ip_level_sample_index(v->dims[2], level, origin[2] + z));
                    if (ip_sample_get(dst, l->type, i) != want[i])
                        sample_errors++;
                }
        float lo, hi;
        uint32_t all_lo[3] = {0, 0, 0}, all_hi[3] = {extent[0] - 1, extent[1] - 1, extent[2] - 1};
        box_range(want, extent, all_lo, all_hi, &lo, &hi);
        for (uint32_t cz = 0, j = 0; cz < per; cz++)
            for (uint32_t cy = 0; cy < per; cy++)
                for (uint32_t cx = 0; cx < per; cx++, j += 2) {
                    uint32_t c[3] = {cx, cy, cz}, b0[3], b1[3];
                    int empty = 0;
                    for (int a = 0; a < 3; a++) {
                        b0[a] = c[a] * l->subblock_edge;
                        b1[a] = b0[a] + l->subblock_edge < extent[a] - 1 ? b0[a] + l->subblock_edge
                                                                         : extent[a] - 1;
                        empty |= b0[a] >= extent[a] - 1;
                    }
                    if (empty)
                        sub[j] = INFINITY, sub[j + 1] = -INFINITY;
                    else
                        box_range(want, extent, b0, b1, &sub[j], &sub[j + 1]);
                }
        float range[2];
        ip_store_brick_range(s, g, range);
        if (range[0] != lo || range[1] != hi)
            range_errors++;
        const float *stored = ip_store_subblock_ranges(s, g);
        for (uint32_t i = 0; i < 2 * per * per * per; i++)
            if (stored[i] != sub[i])
                range_errors++;
        ip_brick_entry e;
        ip_store_brick_entry(s, g, &e);
        if ((e.encoding == IP_BRICK_CONSTANT) != (lo == hi))
            range_errors++;
    }
    CHECK_MSG(sample_errors == 0, "%s: %d samples differ", ibv, sample_errors);
    CHECK_MSG(range_errors == 0, "%s: %d summaries differ", ibv, range_errors);
    CHECK_EQ(ip_store_verify_octree(s, &err), IP_OK);
    float level_lo = INFINITY, level_hi = -INFINITY;
    for (size_t i = 0; i < (size_t)v->dims[0] * v->dims[1] * v->dims[2]; i++)
        level_lo = fminf(level_lo, v->values[i]), level_hi = fmaxf(level_hi, v->values[i]);
    CHECK_EQ(l->value_min, level_lo);
    CHECK_EQ(l->value_max, level_hi);
    free(dst);
    free(work);
    free(sub);
    free(want);
    ip_store_close(s);
}

/* Bricks `input` into `ibv` (replaced) with options `o`; 0, or -1 with the error printed. */
static int brick_with(const char *input, const char *ibv, ip_bricker_options *o,
                      ip_bricker_report *report)
{
    ip_input_desc desc;
    ip_error err;
    o->force = 1;
    if (ip_input_describe(input, NULL, &desc, &err) != IP_OK ||
        ip_bricker_run(&desc, ibv, o, report, &err) != IP_OK) {
        fprintf(stderr, "%s\n", err.message);
        return -1;
    }
    return 0;
}

static int brick_file_at(const char *raw, const char *ibv, uint32_t b, uint32_t s, unsigned threads,
                         int level, ip_bricker_report *report)
{
    ip_bricker_options o;
    ip_bricker_options_default(&o);
    o.brick_edge = b;
    o.subblock_edge = s;
    o.threads = threads;
    o.lz4_level = level;
    return brick_with(raw, ibv, &o, report);
}

static int brick_file(const char *raw, const char *ibv, uint32_t b, uint32_t s, unsigned threads,
                      ip_bricker_report *report)
{
    return brick_file_at(raw, ibv, b, s, threads, IP_LZ4_FAST, report);
}

/* High compression also tries the median edge predictor: its decoder must round-trip too. */
static void round_trip_hc(const char *dir, ip_type type)
{
    char raw[4096], ibv[4200];
    uint32_t dims[3] = {47, 35, 29};
    volume v = make_volume(dir, dims, type, 0, raw, sizeof raw);
    snprintf(ibv, sizeof ibv, "%s.hc.ibv", raw);
    CHECK_MSG(brick_file_at(raw, ibv, 16, 4, 2, IP_LZ4_HC_DEFAULT, NULL) == 0, "%s", raw);
    check_file(ibv, &v);
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open(ibv, &s, &err) == IP_OK);
    int med = 0;
    for (uint64_t g = 0; g < ip_store_layout(s)->brick_count; g++) {
        ip_brick_entry e;
        ip_store_brick_entry(s, g, &e);
        med += (e.filters & IP_FILTER_MED) != 0;
    }
    ip_store_close(s);
    CHECK_MSG(med > 0, "%s: no brick exercised the median edge predictor", ip_type_name(type));
    printf("test_bricker: %s with --hc: %d bricks use the median edge predictor\n",
           ip_type_name(type), med);
    free(v.values);
}

static void round_trip_on(const char *dir, uint32_t x, uint32_t y, uint32_t z, ip_type type,
                          int fill, uint32_t b, uint32_t s, unsigned threads)
{
    char raw[4096], ibv[4200];
    uint32_t dims[3] = {x, y, z};
    volume v = make_volume(dir, dims, type, fill, raw, sizeof raw);
    snprintf(ibv, sizeof ibv, "%s.b%u.s%u.ibv", raw, b, s);
    ip_bricker_report r;
    CHECK_MSG(brick_file(raw, ibv, b, s, threads, &r) == 0, "%s", raw);
    check_file(ibv, &v);
    if (fill == FILL_CONSTANT)
        CHECK_EQ(r.bricks_constant, r.bricks);
    if (fill == FILL_NOISE)
        CHECK_EQ(r.bricks_constant, 0);
    free(v.values);
}

static void round_trip(const char *dir, uint32_t x, uint32_t y, uint32_t z, ip_type type, int fill,
                       uint32_t b, uint32_t s)
{
    round_trip_on(dir, x, y, z, type, fill, b, s, 2);
}

static int read_file(const char *path, unsigned char **data, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    fseek(f, 0, SEEK_END);
    *size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    *data = malloc(*size ? *size : 1);
    size_t got = fread(*data, 1, *size, f);
    fclose(f);
    return got == *size ? 0 : -1;
}

/* Whether the files at a and b are both readable and hold the same bytes. */
static int same_files(const char *a, const char *b)
{
    unsigned char *da = NULL, *db = NULL;
    size_t sa = 0, sb = 0;
    int same = read_file(a, &da, &sa) == 0 && read_file(b, &db, &sb) == 0 && sa == sb &&
               memcmp(da, db, sa) == 0;
    free(da);
    free(db);
    return same;
}

static void test_deterministic(void)
{
    const char *dir = scratch_dir;
    char raw[4096], a[4200], b[4200];
    uint32_t dims[3] = {70, 41, 37};
    volume v = make_volume(dir, dims, IP_UINT16, 0, raw, sizeof raw);
    snprintf(a, sizeof a, "%s/t1.ibv", dir);
    snprintf(b, sizeof b, "%s/t3.ibv", dir);
    REQUIRE(brick_file(raw, a, 8, 4, 1, NULL) == 0 && brick_file(raw, b, 8, 4, 3, NULL) == 0);
    CHECK_MSG(same_files(a, b), "%s and %s differ", a, b);
    free(v.values);
}

static int cancel_half(void *user, uint64_t done, uint64_t total)
{
    (void)user;
    return done * 2 >= total;
}

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d));)
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    if (d)
        closedir(d);
    return n;
}

static void test_cancel_and_limits(void)
{
    const char *dir = scratch_dir;
    char sub[4200], raw[4460], out[4400];
    snprintf(sub, sizeof sub, "%s/cancel", dir);
    mkdir(sub, 0777);
    uint32_t dims[3] = {50, 40, 90};
    volume v = make_volume(sub, dims, IP_UINT8, 0, raw, sizeof raw);
    snprintf(out, sizeof out, "%s/out.ibv", sub);
    ip_input_desc desc;
    ip_error err;
    ip_bricker_options o;
    REQUIRE(ip_input_describe(raw, NULL, &desc, &err) == IP_OK);
    ip_bricker_options_default(&o);
    o.brick_edge = 8;
    o.progress = cancel_half;
    CHECK_EQ(ip_bricker_run(&desc, out, &o, NULL, &err), IP_ERR_CANCELLED);
    CHECK_NE(access(out, F_OK), 0);
    CHECK_EQ(count_entries(sub), 1); /* only the input: no temporary or spill file left */

    o.progress = NULL;
    o.memory_limit = 1024;
    CHECK_EQ(ip_bricker_run(&desc, out, &o, NULL, &err), IP_ERR_LIMIT);
    CHECK_CONTAINS(err.message, "MiB");
    CHECK_NE(access(out, F_OK), 0);

    o.memory_limit = 0;
    CHECK_EQ(ip_bricker_run(&desc, out, &o, NULL, &err), IP_OK);
    CHECK_EQ(ip_bricker_run(&desc, out, &o, NULL, &err), IP_ERR_EXISTS);
    CHECK_CONTAINS(err.message, "out.ibv");
    o.force = 1;
    CHECK_EQ(ip_bricker_run(&desc, out, &o, NULL, &err), IP_OK);
    CHECK_EQ(count_entries(sub), 2);
    free(v.values);
}

/* The plan is a count of what the run allocates: for the head upsampled 6 times (3072 x 3072 x
 * 1404 uint16, 26.5 GB) on 2 threads under a limit of 1 GiB it fits, holds the level-0 slab
 * (33 planes) and no second chunk, and a volume 10 times deeper adds only 48 bytes per brick
 * (directory entry, brick range, octree node share, Morton order): the sub-block ranges wait on
 * disk. Without the limit the plan holds a second chunk (32 more planes) to read while one is
 * encoded; the head upsampled 4 times (2048 x 2048 x 936) has room for it in 1 GiB. */
static void test_memory_plan(void)
{
    ip_input_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.dims[0] = 3072;
    desc.dims[1] = 3072;
    desc.dims[2] = 1404;
    desc.type = IP_UINT16;
    desc.spacing[0] = desc.spacing[1] = desc.spacing[2] = 1;
    ip_bricker_options o;
    ip_bricker_options_default(&o);
    o.threads = 2;
    o.memory_limit = (uint64_t)1024 << 20;
    uint64_t plan = 0, deeper = 0, roomy = 0, x4 = 0;
    ip_error err;
    REQUIRE(ip_bricker_memory_needed(&desc, &o, &plan, &err) == IP_OK);
    CHECK_MSG(plan <= (uint64_t)1024 << 20, "plan %llu bytes", (unsigned long long)plan);
    CHECK_GE(plan, (uint64_t)33 * 3072 * 3072 * 2);
    o.memory_limit = 0;
    REQUIRE(ip_bricker_memory_needed(&desc, &o, &roomy, &err) == IP_OK);
    CHECK_EQ(roomy - plan, (uint64_t)32 * 3072 * 3072 * 2);
    desc.dims[0] = desc.dims[1] = 2048;
    desc.dims[2] = 936;
    o.memory_limit = (uint64_t)1024 << 20;
    REQUIRE(ip_bricker_memory_needed(&desc, &o, &x4, &err) == IP_OK);
    CHECK_MSG(x4 >= (uint64_t)65 * 2048 * 2048 * 2 && x4 <= (uint64_t)1024 << 20, "plan %llu bytes",
              (unsigned long long)x4);
    desc.dims[0] = desc.dims[1] = 3072; /* and the limit of 1 GiB still */
    desc.dims[2] = 14040;
    REQUIRE(ip_bricker_memory_needed(&desc, &o, &deeper, &err) == IP_OK);
    uint64_t more_bricks = (uint64_t)96 * 96 * (14040 / 32 - 1404 / 32) * 8 / 7 + 1;
    CHECK_MSG(deeper - plan <= more_bricks * 48, "plan grows by %llu bytes",
              (unsigned long long)(deeper - plan));
    /* one layer of level-0 bricks (32 planes): nothing to read while it is encoded, so no
     * second chunk even without a limit; a limit of 1 byte gives the smallest plan */
    uint64_t one_layer = 0, smallest = 0;
    desc.dims[2] = 32;
    o.memory_limit = 0;
    REQUIRE(ip_bricker_memory_needed(&desc, &o, &one_layer, &err) == IP_OK);
    o.memory_limit = 1;
    REQUIRE(ip_bricker_memory_needed(&desc, &o, &smallest, &err) == IP_OK);
    CHECK_MSG(one_layer == smallest, "plans of %llu and %llu bytes", (unsigned long long)one_layer,
              (unsigned long long)smallest);
}

/* Bricks `input` with 8-cell bricks on 2 threads under `limit` bytes (0: none). */
static int brick_limited(const char *input, const char *ibv, uint64_t limit,
                         ip_bricker_report *report)
{
    ip_bricker_options o;
    ip_bricker_options_default(&o);
    o.brick_edge = 8;
    o.subblock_edge = 4;
    o.threads = 2;
    o.memory_limit = limit;
    return brick_with(input, ibv, &o, report);
}

/* Whether the file system under `path` reads it with O_DIRECT (4 KiB at 0 into an aligned
 * buffer), as the bricker will try to. */
static int direct_reads_work(const char *path)
{
    int fd = open(path, O_RDONLY | O_DIRECT);
    void *buf = NULL;
    int ok = fd >= 0 && posix_memalign(&buf, 4096, 4096) == 0 && pread(fd, buf, 4096, 0) == 4096;
    free(buf);
    if (fd >= 0)
        close(fd);
    return ok;
}

/* Direct and buffered reads, overlapped with the encoding or not, give the same file. The
 * samples of a raw file whose planes suit O_DIRECT (256 x 256 uint16: 128 KiB planes, 5 chunks
 * of 8-cell bricks) are bricked: as they are, the next chunk read while one is encoded; under a
 * memory limit that leaves no room for the second chunk; and behind 100 bytes of a MetaImage
 * HeaderSize, an offset no direct read meets, so that every read goes through the page cache. */
static void test_direct_reads(void)
{
    const char *dir = scratch_dir;
    char sub[4200], raw[4096], skewed[4400], mhd[4400], a[4400], b[4400], c[4400];
    snprintf(sub, sizeof sub, "%s/direct", dir);
    mkdir(sub, 0777);
    uint32_t dims[3] = {256, 256, 41};
    volume v = make_volume(sub, dims, IP_UINT16, FILL_PATTERN, raw, sizeof raw);
    snprintf(skewed, sizeof skewed, "%s/skewed.dat", sub);
    snprintf(mhd, sizeof mhd, "%s/skewed.mhd", sub);
    unsigned char *bytes;
    size_t size;
    REQUIRE(read_file(raw, &bytes, &size) == 0);
    unsigned char header[100];
    memset(header, 'h', sizeof header);
    FILE *f = fopen(skewed, "wb");
    REQUIRE(f && fwrite(header, 1, sizeof header, f) == sizeof header);
    REQUIRE(fwrite(bytes, 1, size, f) == size && fclose(f) == 0);
    free(bytes);
    f = fopen(mhd, "w");
    REQUIRE(f);
    fprintf(f, "ObjectType = Image\nNDims = 3\nDimSize = 256 256 41\nElementType = MET_USHORT\n"
               "HeaderSize = 100\nElementDataFile = skewed.dat\n");
    REQUIRE(fclose(f) == 0);
    snprintf(a, sizeof a, "%s/overlap.ibv", sub);
    snprintf(b, sizeof b, "%s/serial.ibv", sub);
    snprintf(c, sizeof c, "%s/buffered.ibv", sub);

    ip_input_desc desc;
    ip_bricker_options o;
    ip_error err;
    uint64_t least = 0, most = 0;
    REQUIRE(ip_input_describe(raw, NULL, &desc, &err) == IP_OK);
    ip_bricker_options_default(&o);
    o.brick_edge = 8;
    o.subblock_edge = 4;
    o.threads = 2;
    REQUIRE(ip_bricker_memory_needed(&desc, &o, &most, &err) == IP_OK);
    o.memory_limit = 1; /* no plan fits: the answer is the smallest plan */
    REQUIRE(ip_bricker_memory_needed(&desc, &o, &least, &err) == IP_OK);
    /* the second chunk: 8 planes of 128 KiB, in whole 2 MiB pages */
    CHECK_MSG(most > least, "plans of %llu and %llu bytes", (unsigned long long)most,
              (unsigned long long)least);

    ip_bricker_report ra, rb, rc;
    REQUIRE(brick_limited(raw, a, 0, &ra) == 0);
    REQUIRE(brick_limited(raw, b, least, &rb) == 0);
    REQUIRE(brick_limited(mhd, c, 0, &rc) == 0);
    CHECK(ra.read_overlap);
    CHECK(!rb.read_overlap);
    CHECK(rc.read_overlap);
    CHECK_EQ(ra.memory_planned, most);
    CHECK_EQ(rb.memory_planned, least);
    int direct = direct_reads_work(raw);
    printf("test_bricker: O_DIRECT reads %s here: %llu and %llu of %llu bytes read directly\n",
           direct ? "work" : "do not work", (unsigned long long)ra.bytes_direct,
           (unsigned long long)rb.bytes_direct, (unsigned long long)ra.input_bytes);
    if (direct) {
        CHECK_EQ(ra.bytes_direct, ra.input_bytes);
        CHECK_EQ(rb.bytes_direct, rb.input_bytes);
    }
    CHECK_EQ(rc.bytes_direct, 0);
    check_file(a, &v);
    CHECK_MSG(same_files(a, b), "%s and %s differ", a, b);
    CHECK_MSG(same_files(a, c), "%s and %s differ", a, c);
    free(v.values);
}

static void test_shared_data(void)
{
    const char *dir = scratch_dir;
    const char *data = getenv("IP_SKIP_SHARED_DATA") ? NULL : getenv("IP_SHARED_DATA");
    DIR *d = data ? opendir(data) : NULL;
    if (!d) {
        printf("test_bricker: skipping the shared volumes: %s is absent\n",
               data ? data : "IP_SHARED_DATA");
        return;
    }
    for (struct dirent *e; (e = readdir(d));) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 4, ".raw") != 0)
            continue;
        char raw[4096], ibv[4400];
        snprintf(raw, sizeof raw, "%s/%s", data, e->d_name);
        snprintf(ibv, sizeof ibv, "%s/%s.ibv", dir, e->d_name);
        ip_input_desc desc;
        ip_error err;
        REQUIRE(ip_input_describe(raw, NULL, &desc, &err) == IP_OK);
        volume v = {{desc.dims[0], desc.dims[1], desc.dims[2]}, desc.type, NULL};
        size_t n = (size_t)v.dims[0] * v.dims[1] * v.dims[2];
        unsigned char *bytes = malloc(n * ip_type_size(v.type));
        v.values = malloc(n * sizeof(float));
        ip_input_reader *reader;
        REQUIRE(bytes && v.values && ip_input_open(&desc, &reader, &err) == IP_OK);
        REQUIRE(ip_input_read_planes(reader, bytes, v.dims[2], &err) == IP_OK);
        ip_input_close(reader);
        for (size_t i = 0; i < n; i++)
            v.values[i] = ip_sample_get(bytes, v.type, i);
        free(bytes);
        CHECK_MSG(brick_file(raw, ibv, IP_DEFAULT_BRICK_EDGE, IP_DEFAULT_SUBBLOCK_EDGE, 2, NULL) ==
                      0,
                  "%s", raw);
        check_file(ibv, &v);
        unlink(ibv);
        free(v.values);
        printf("test_bricker: round trip of %s\n", e->d_name);
    }
    closedir(d);
}

static void test_round_trips(void)
{
    const char *dir = scratch_dir;
    for (int t = 0; t < IP_TYPE_COUNT; t++) {
        round_trip(dir, 2, 2, 2, (ip_type)t, 0, 32, 8);      /* tiny */
        round_trip(dir, 103, 94, 161, (ip_type)t, 0, 32, 8); /* odd dims */
        round_trip(dir, 33, 17, 9, (ip_type)t, 0, 8, 2);     /* cells a multiple of B */
        round_trip(dir, 32, 16, 8, (ip_type)t, 0, 8, 2);     /* samples a multiple of B */
        round_trip(dir, 40, 30, 20, (ip_type)t, 1, 8, 4);    /* constant */
        round_trip(dir, 37, 2, 29, (ip_type)t, 0, 4, 4);     /* flat axis, many levels */
        /* noise: every sub-block range checked against the samples, several layers and brick
         * rows per level, layers summarised by 1 to 3 threads */
        round_trip_on(dir, 131, 77, 70, (ip_type)t, FILL_NOISE, 32, 8, 3);
        round_trip_on(dir, 131, 77, 70, (ip_type)t, FILL_NOISE, 16, 4, 1);
        round_trip_on(dir, 45, 52, 39, (ip_type)t, FILL_NOISE, 8, 2, 2);
    }
}

static void test_round_trips_hc(void)
{
    for (int t = 0; t < IP_TYPE_COUNT; t++)
        round_trip_hc(scratch_dir, (ip_type)t);
}

static const test_case cases[] = {
    TEST_CASE(test_round_trips),   TEST_CASE(test_round_trips_hc),
    TEST_CASE(test_deterministic), TEST_CASE(test_cancel_and_limits),
    TEST_CASE(test_memory_plan),   TEST_CASE(test_direct_reads),
    TEST_CASE(test_shared_data),
};

static void make_scratch_dir(void)
{
    scratch_dir = test_tmp_dir("test_bricker");
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_bricker", make_scratch_dir, NULL);
}
