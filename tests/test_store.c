/* SPDX-License-Identifier: BSD-3-Clause */
/* The store against a hostile or changing file: what it checks on opening (the padding before
 * the summary, reserved directory bytes, non-regular files), and what a reader gets when the
 * file changes after opening (truncated, rewritten in place): a clear error naming the file
 * and the brick, never a signal and never unverified samples. */
#include <fcntl.h>
#include <math.h>
#include <sys/stat.h>
#include <sys/vfs.h>
#include <unistd.h>

#include "check.h"
#include "format.h"
#include "internal.h"
#include "isoprop/bricker.h"
#include "isoprop/generate.h"
#include "isoprop/store.h"

/* What the cases share: the scratch folder and a brick file in it (make_file()). */
static const char *scratch_dir;
static char scratch_ibv[4200];

/* Volume `p` written as STEM's raw file in dir and bricked with 4-cell bricks, 2-cell
 * sub-blocks, into dir/STEM.ibv (its path in ibv). */
static void make_volume(const char *dir, const ip_gen_params *p, const char *stem, char *ibv,
                        size_t size)
{
    char name[256], raw[4400];
    ip_error err;
    REQUIRE(ip_raw_file_name(name, sizeof name, stem, p->dims, p->type) == IP_OK);
    snprintf(raw, sizeof raw, "%s/%s", dir, name);
    REQUIRE(ip_generate_write(p, raw, 1, &err) == IP_OK);
    snprintf(ibv, size, "%s/%s.ibv", dir, stem);
    ip_input_desc d;
    ip_bricker_options o;
    REQUIRE(ip_input_describe(raw, NULL, &d, &err) == IP_OK);
    ip_bricker_options_default(&o);
    o.brick_edge = 4;
    o.subblock_edge = 2;
    o.force = 1;
    REQUIRE(ip_bricker_run(&d, ibv, &o, NULL, &err) == IP_OK);
}

/* A gyroid: many payloads, several levels. */
static void make_file(const char *dir, char *ibv, size_t size)
{
    ip_gen_params p = {sizeof(ip_gen_params), IP_FIELD_GYROID, {21, 18, 19}, IP_UINT16, 0.0, 1};
    make_volume(dir, &p, "gyroid", ibv, size);
}

static unsigned char *read_whole(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    REQUIRE(f && fseek(f, 0, SEEK_END) == 0);
    *size = (size_t)ftell(f);
    unsigned char *bytes = malloc(*size);
    REQUIRE(bytes && fseek(f, 0, SEEK_SET) == 0 && fread(bytes, 1, *size, f) == *size);
    fclose(f);
    return bytes;
}

static void write_whole(const char *path, const unsigned char *bytes, size_t size)
{
    FILE *f = fopen(path, "wb");
    REQUIRE(f && fwrite(bytes, 1, size, f) == size && fclose(f) == 0);
}

/* Writes bytes at `offset` of an existing file, in place (same inode, same size). */
static void poke(const char *path, uint64_t offset, const void *bytes, size_t size)
{
    int fd = open(path, O_WRONLY);
    REQUIRE(fd >= 0 && pwrite(fd, bytes, size, (off_t)offset) == (ssize_t)size);
    close(fd);
}

/* Opening `bytes` (written to `path`) fails with `code` and a message holding `text`. */
static void open_fails(const char *path, const unsigned char *bytes, size_t size, ip_status code,
                       const char *text)
{
    write_whole(path, bytes, size);
    ip_store *s = NULL;
    ip_error err;
    ip_status st = ip_store_open(path, &s, &err);
    CHECK_MSG(st == code, "%s: status %d, wanted %d", text, (int)st, (int)code);
    if (st != IP_OK) {
        CHECK_CONTAINS(err.message, path);
        CHECK_CONTAINS(err.message, text);
    }
    ip_store_close(s);
}

/* The first brick with a payload; fills its entry. */
static uint64_t first_payload(const ip_store *s, ip_brick_entry *e)
{
    for (uint64_t g = 0; g < ip_store_layout(s)->brick_count; g++) {
        ip_store_brick_entry(s, g, e);
        if (e->stored_size > 0)
            return g;
    }
    REQUIRE(!"a payload");
    return 0;
}

/* docs/format.md: the padding before the summary section and a directory entry's reserved
 * bytes are zero; a file with anything else there is not one this reader wrote or knows. The
 * checksums are recomputed, so only the rule itself can reject these. */
static void test_zero_fields(void)
{
    const char *dir = scratch_dir, *ibv = scratch_ibv;
    size_t size;
    unsigned char *good = read_whole(ibv, &size);
    ip_layout l;
    REQUIRE(ip__format_parse(good, size, "good", 0, &l, NULL) == IP_OK);
    uint64_t data_end = l.data_offset + l.data_size;
    char path[4200];
    snprintf(path, sizeof path, "%s/hostile.ibv", dir);
    unsigned char *bad = malloc(size);
    REQUIRE(bad);

    REQUIRE(l.summary_offset > data_end); /* this file has padding */
    memcpy(bad, good, size);
    bad[l.summary_offset - 1] = 0x5a;
    open_fails(path, bad, size, IP_ERR_FORMAT, "padding before the summary section");

    ip_summary_offsets o;
    ip__summary_offsets_of(&l, &o);
    for (int byte = 14; byte <= 15; byte++) {
        memcpy(bad, good, size);
        unsigned char *entry = bad + l.summary_offset + o.directory + 3 * IP_DIRECTORY_ENTRY_SIZE;
        entry[byte] = 1;
        uint64_t sum = ip__format_checksum(bad + l.summary_offset, l.summary_size);
        for (int i = 0; i < 8; i++) /* header byte 128: the summary checksum */
            bad[128 + i] = (unsigned char)(sum >> (8 * i));
        uint64_t head = ip__format_checksum(bad, 248);
        for (int i = 0; i < 8; i++)
            bad[248 + i] = (unsigned char)(head >> (8 * i));
        open_fails(path, bad, size, IP_ERR_FORMAT, "brick 3");
        open_fails(path, bad, size, IP_ERR_FORMAT, "reserved bytes");
    }

    /* the untouched bytes still open: the rules above reject only what they name */
    memcpy(bad, good, size);
    open_fails(path, bad, size, IP_OK, "");
    /* a truncated or extended file fails on its size */
    open_fails(path, good, size - 1, IP_ERR_FORMAT, "truncated or extended");
    memcpy(bad, good, size);
    free(bad);
    bad = calloc(size + 100, 1);
    REQUIRE(bad);
    memcpy(bad, good, size);
    open_fails(path, bad, size + 100, IP_ERR_FORMAT, "truncated or extended");
    free(bad);
    free(good);
}

/* A FIFO (or any non-regular file) is refused at once: opening it for reading would wait for a
 * writer forever. The test would hang, not fail, without the fix: ctest's timeout catches it. */
static void test_not_regular(void)
{
    const char *dir = scratch_dir;
    char fifo[4200];
    snprintf(fifo, sizeof fifo, "%s/fifo.ibv", dir);
    REQUIRE(mkfifo(fifo, 0600) == 0);
    ip_store *s = NULL;
    ip_error err;
    CHECK_EQ(ip_store_open(fifo, &s, &err), IP_ERR_IO);
    CHECK_CONTAINS(err.message, fifo);
    CHECK_CONTAINS(err.message, "not a regular file");
    CHECK_EQ(ip_store_open(dir, &s, &err), IP_ERR_IO);
    CHECK_CONTAINS(err.message, "not a regular file");
    unlink(fifo);
}

/* The file shrinks after opening: reading a brick past the new end is an I/O error naming the
 * file, the brick and both sizes; bricks still inside the file read as before. */
static void test_truncated_while_open(void)
{
    const char *dir = scratch_dir, *ibv = scratch_ibv;
    char path[4200], cmd[9000];
    snprintf(path, sizeof path, "%s/shrinks.ibv", dir);
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", ibv, path);
    REQUIRE(system(cmd) == 0);
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open(path, &s, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    void *dst = malloc(ip_store_brick_samples(s, 0) * 8 + 4096);
    void *work = malloc(ip_store_read_work_size(s));
    REQUIRE(dst && work);
    ip_brick_entry first;
    uint64_t g0 = first_payload(s, &first);
    /* cut the file in the middle of the last payload */
    uint64_t last = g0, cut = 0;
    for (uint64_t g = 0; g < l->brick_count; g++) {
        ip_brick_entry e;
        ip_store_brick_entry(s, g, &e);
        if (e.stored_size > 1 && e.offset > cut) {
            cut = e.offset + e.stored_size / 2;
            last = g;
        }
    }
    REQUIRE(last != g0 && truncate(path, (off_t)cut) == 0);
    CHECK_EQ(ip_store_read_brick(s, g0, dst, work, &err), IP_OK);
    CHECK_EQ(ip_store_read_brick(s, last, dst, work, &err), IP_ERR_IO);
    CHECK_CONTAINS(err.message, path);
    char brick[64], sizes[96];
    snprintf(brick, sizeof brick, "brick %llu ", (unsigned long long)last);
    snprintf(sizes, sizeof sizes, "ends at byte %llu", (unsigned long long)cut);
    CHECK_CONTAINS(err.message, brick);
    CHECK_CONTAINS(err.message, sizes);
    CHECK_CONTAINS(err.message, "truncated or rewritten");
    /* to nothing at all: every payload is then past the end */
    REQUIRE(truncate(path, 0) == 0);
    CHECK_EQ(ip_store_read_brick(s, g0, dst, work, &err), IP_ERR_IO);
    CHECK_CONTAINS(err.message, "ends at byte 0");
    ip_store_close(s);
    free(dst);
    free(work);
}

/* Bytes rewritten in place after opening: the payload read is the payload checked, so the
 * brick fails its checksum; the summaries were read at open and stay as verified. */
static void test_rewritten_while_open(void)
{
    const char *dir = scratch_dir, *ibv = scratch_ibv;
    char path[4200], cmd[9000];
    snprintf(path, sizeof path, "%s/rewritten.ibv", dir);
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", ibv, path);
    REQUIRE(system(cmd) == 0);
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open(path, &s, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    void *dst = malloc(ip_store_brick_samples(s, 0) * 8 + 4096);
    void *work = malloc(ip_store_read_work_size(s));
    REQUIRE(dst && work);
    ip_brick_entry e;
    uint64_t g = first_payload(s, &e);
    float before[2];
    ip_store_brick_range(s, g, before);
    static const unsigned char junk[16] = {0xde, 0xad, 0xbe, 0xef, 1, 2,  3,  4,
                                           5,    6,    7,    8,    9, 10, 11, 12};
    poke(path, e.offset, junk, e.stored_size < sizeof junk ? e.stored_size : sizeof junk);
    poke(path, l->summary_offset + 16, junk, sizeof junk); /* the summary too */
    CHECK_EQ(ip_store_read_brick(s, g, dst, work, &err), IP_ERR_CHECKSUM);
    CHECK_CONTAINS(err.message, path);
    float after[2];
    ip_store_brick_range(s, g, after);
    CHECK_MEM_EQ(before, after, sizeof before);
    ip_store_close(s);
    /* reopened, the file fails as a whole: its summary no longer matches its checksum */
    CHECK_EQ(ip_store_open(path, &s, &err), IP_ERR_CHECKSUM);
    CHECK_CONTAINS(err.message, "summary section checksum");
    free(dst);
    free(work);
}

/* Reading every brick of a good file: each decodes, and its scratch is what the store says. */
static void test_reads(void)
{
    const char *ibv = scratch_ibv;
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open(ibv, &s, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    size_t most = 0;
    for (uint64_t g = 0; g < l->brick_count; g++)
        if (ip_store_brick_samples(s, g) > most)
            most = ip_store_brick_samples(s, g);
    void *dst = malloc(most * ip_type_size(l->type));
    void *work = malloc(ip_store_read_work_size(s));
    REQUIRE(dst && work);
    int bad = 0;
    for (uint64_t g = 0; g < l->brick_count; g++)
        bad += ip_store_verify_brick(s, g, dst, work, &err) != IP_OK;
    CHECK_MSG(bad == 0, "%d bricks failed: %s", bad, err.message);
    CHECK_EQ(ip_store_verify_octree(s, &err), IP_OK);
    ip_store_close(s);
    free(dst);
    free(work);
}

/* The accessors without a test through the others: the path, the octree's node ranges (the
 * top node of each level covers all its bricks), ip_store_check_summary() on good and altered
 * samples, and the prefetch hint (which must leave reads unchanged). */
static void test_accessors(void)
{
    const char *ibv = scratch_ibv;
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open(ibv, &s, &err) == IP_OK);
    CHECK_STR_EQ(ip_store_path(s), ibv);
    const ip_layout *l = ip_store_layout(s);
    CHECK_GT(l->level_count, 1);
    for (uint32_t k = 0; k < l->level_count; k++) {
        const ip_level_layout *lv = &l->levels[k];
        float lo = INFINITY, hi = -INFINITY, r[2];
        for (uint64_t g = lv->first_brick; g < lv->first_brick + lv->brick_count; g++) {
            ip_store_brick_range(s, g, r);
            lo = r[0] < lo ? r[0] : lo;
            hi = r[1] > hi ? r[1] : hi;
        }
        const uint32_t root[3] = {0, 0, 0};
        const float *top = ip_store_node_range(s, k, lv->octree_depth, root);
        CHECK_MSG(top[0] == lo && top[1] == hi, "level %u: top node [%g, %g], bricks [%g, %g]", k,
                  top[0], top[1], lo, hi);
        CHECK_EQ(lv->value_min, lo);
        CHECK_EQ(lv->value_max, hi);
        /* depth 0 is the brick grid itself */
        const uint32_t last[3] = {lv->bricks[0] - 1, lv->bricks[1] - 1, lv->bricks[2] - 1};
        ip_store_brick_range(s, ip_brick_global_index(l, k, last), r);
        const float *node = ip_store_node_range(s, k, 0, last);
        CHECK_EQ(node[0], r[0]);
        CHECK_EQ(node[1], r[1]);
    }
    ip_brick_entry e;
    uint64_t g = first_payload(s, &e);
    uint64_t count = ip_store_brick_samples(s, g);
    uint16_t *dst = malloc(count * sizeof *dst);
    void *work = malloc(ip_store_read_work_size(s));
    REQUIRE(dst && work && l->type == IP_UINT16);
    ip_store_prefetch_brick(s, g);
    REQUIRE(ip_store_read_brick(s, g, dst, work, &err) == IP_OK);
    CHECK_EQ(ip_store_check_summary(s, g, dst, &err), IP_OK);
    float range[2];
    ip_store_brick_range(s, g, range);
    /* one sample past the brick's maximum, then one sample moved inside the range but into a
     * sub-block whose range it leaves */
    uint16_t kept = dst[count - 1];
    dst[count - 1] = (uint16_t)(range[1] < 65535 ? range[1] + 1 : 0);
    CHECK_EQ(ip_store_check_summary(s, g, dst, &err), IP_ERR_CORRUPT);
    CHECK_CONTAINS(err.message, ibv);
    CHECK_CONTAINS(err.message, "samples disagree with the summary");
    dst[count - 1] = kept;
    /* sample 0 lies in sub-block 0 only, whose range is narrower than the brick's here */
    const float *sub = ip_store_subblock_ranges(s, g);
    REQUIRE(sub[0] > range[0] || sub[1] < range[1]);
    dst[0] = (uint16_t)(sub[0] > range[0] ? range[0] : range[1]);
    CHECK_EQ(ip_store_check_summary(s, g, dst, &err), IP_ERR_CORRUPT);
    CHECK_CONTAINS(err.message, "samples disagree with the summary");
    REQUIRE(ip_store_read_brick(s, g, dst, work, &err) == IP_OK);
    CHECK_EQ(ip_store_check_summary(s, g, dst, &err), IP_OK);
    ip_store_close(s);
    free(dst);
    free(work);
}

/* A small uint8 phantom, bricked as `name`.ibv in dir: both constant and stored bricks. */
static void make_phantom(const char *dir, const char *name, char *ibv, size_t size)
{
    ip_gen_params p = {sizeof(ip_gen_params), IP_FIELD_SHEPP_LOGAN, {40, 36, 33}, IP_UINT8, 0.0, 1};
    make_volume(dir, &p, name, ibv, size);
}

/* The sub-block ranges as the store holds them (those of uniform bricks shared by value) are
 * the file's, bit for bit, for every brick; the store holds less than the summary section. */
static void test_compact_summaries(void)
{
    const char *dir = scratch_dir;
    char ibv[4400];
    ip_error err;
    make_phantom(dir, "phantom", ibv, sizeof ibv);
    size_t size;
    unsigned char *file = read_whole(ibv, &size);
    ip_store *s = NULL;
    REQUIRE(ip_store_open(ibv, &s, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    ip_summary_offsets off;
    ip__summary_offsets_of(l, &off);
    uint32_t sub = ip_layout_subblocks_per_brick(l);
    uint64_t constant = 0, mismatches = 0;
    for (uint64_t g = 0; g < l->brick_count; g++) {
        ip_brick_entry e;
        ip_store_brick_entry(s, g, &e);
        constant += e.encoding == IP_BRICK_CONSTANT;
        const float *held = ip_store_subblock_ranges(s, g);
        const unsigned char *stored =
            file + l->summary_offset + off.subblock_ranges + g * sub * IP_RANGE_SIZE;
        for (uint32_t i = 0; i < 2 * sub; i++) {
            uint32_t a, b = ip__load_u32le(stored + 4 * i);
            memcpy(&a, &held[i], 4);
            mismatches += a != b;
        }
    }
    CHECK_GT(constant, 0);
    CHECK_LT(constant, l->brick_count); /* both kinds are exercised */
    CHECK_EQ(mismatches, 0);
    CHECK_GT(ip_store_summary_memory(s), 0);
    CHECK_LT(ip_store_summary_memory(s), l->summary_size);
    ip_store_close(s);
    free(file);
}

/* ip_store_brick_in_memory(): 1 for every brick once the file has just been read whole, 0 for
 * a payload brick once the kernel has dropped the file's pages (unless the file system keeps
 * files in memory), 1 for a constant brick whatever the page cache holds; -1 only where the
 * kernel cannot tell, and then throughout. */
static void test_in_memory(void)
{
    const char *dir = scratch_dir;
    char ibv[4400];
    ip_error err;
    make_phantom(dir, "in_memory", ibv, sizeof ibv);
    size_t size;
    free(read_whole(ibv, &size));
    ip_store *s = NULL;
    REQUIRE(ip_store_open(ibv, &s, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    ip_brick_entry e;
    uint64_t g = first_payload(s, &e), constant = UINT64_MAX;
    for (uint64_t i = 0; i < l->brick_count && constant == UINT64_MAX; i++) {
        ip_brick_entry c;
        ip_store_brick_entry(s, i, &c);
        if (c.encoding == IP_BRICK_CONSTANT)
            constant = i;
    }
    REQUIRE(constant != UINT64_MAX);
    int in = ip_store_brick_in_memory(s, g);
    if (in < 0) {
        printf("test_store: the kernel cannot tell what the page cache holds here\n");
        ip_store_close(s);
        return;
    }
    int all = 1;
    for (uint64_t i = 0; i < l->brick_count; i++)
        all &= ip_store_brick_in_memory(s, i) == 1;
    CHECK(all);
    int fd = open(ibv, O_RDONLY);
    REQUIRE(fd >= 0);
    struct statfs fs;
    REQUIRE(fstatfs(fd, &fs) == 0);
    int memory_fs = fs.f_type == 0x01021994 /* tmpfs */ || fs.f_type == 0x858458f6; /* ramfs */
    /* DONTNEED is advice: a page the kernel holds at that moment (locked, under writeback, read
     * by another process) stays, so it is asked again a few times (a parallel test run once
     * saw the brick still there) */
    for (int tries = 0; tries < 20; tries++) {
        REQUIRE(fdatasync(fd) == 0 && posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED) == 0);
        in = ip_store_brick_in_memory(s, g);
        if (memory_fs || in == 0)
            break;
        usleep(20000);
    }
    close(fd);
    CHECK_MSG(memory_fs ? in == 1 : in == 0, "brick %llu: %d", (unsigned long long)g, in);
    CHECK_EQ(ip_store_brick_in_memory(s, constant), 1);
    ip_store_close(s);
}

static const test_case cases[] = {
    TEST_CASE(test_reads),
    TEST_CASE(test_accessors),
    TEST_CASE(test_zero_fields),
    TEST_CASE(test_not_regular),
    TEST_CASE(test_truncated_while_open),
    TEST_CASE(test_rewritten_while_open),
    TEST_CASE(test_compact_summaries),
    TEST_CASE(test_in_memory),
};

static void make_scratch_file(void)
{
    scratch_dir = test_tmp_dir("test_store");
    make_file(scratch_dir, scratch_ibv, sizeof scratch_ibv);
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_store", make_scratch_file, NULL);
}
