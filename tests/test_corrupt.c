/* SPDX-License-Identifier: BSD-3-Clause */
/* Corrupted and changing brick files never give a wrong image, a crash or a hang.
 *
 * For small brick files made here, every payload brick in turn gets a bit flipped in a copy
 * of the file, and so does every 4 KiB page of the data section get zeroed; each copy goes
 * through the progressive engine (1 and 2 threads, every ray) and ip_extract_full (1 and 2
 * threads), and through isoinfo-style verification. Each run must either fail with a clear
 * error (a non-OK status whose message names the file and the brick) or give exactly the
 * image of the intact file (ip_raster_mesh, pixel for pixel). Counted, and asserted: no
 * silent difference, no unclear error.
 *
 * Then files that change under an open store: truncated to half mid-render (the rest of the
 * render must fail with an error naming the file and saying it is shorter or changed, not die
 * of SIGBUS), and payload bytes overwritten in place mid-render (a checksum error naming the
 * brick, or the intact image; never a different image). Run under ThreadSanitizer too. */
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "format.h"
#include "isoprop/bricker.h"
#include "isoprop/engine.h"
#include "isoprop/generate.h"
#include "isoprop/render.h"
#include "volumes.h"

#define WIDTH 48
#define HEIGHT 36
#define PAGE 4096u
/* Most mutated copies per volume and kind: a deterministic spread when there are more. */
#define MAX_COPIES 128

/* What a run of a corrupted file came to. */
typedef struct tally {
    int runs, errors, identical, silent, unclear;
} tally;

/* A volume, its intact file's bytes and the images of the intact file. */
typedef struct subject {
    char name[64];
    char path[4200];      /* the intact file */
    unsigned char *bytes; /* its content */
    uint64_t size;
    ip_layout layout;
    float iso;
    ip_camera camera;
    double lo[3], hi[3];
    uint8_t *reference[4]; /* progressive 1 thread, 2 threads, full 1 thread, 2 threads */
} subject;

static const char *const run_names[4] = {"progressive, 1 thread", "progressive, 2 threads",
                                         "full, 1 thread", "full, 2 threads"};

static void make_volume(const char *dir, ip_field field, const uint32_t dims[3], ip_type type,
                        uint32_t edge, uint32_t subblock, char *ibv, size_t size)
{
    ip_gen_params p = {sizeof(ip_gen_params), field, {dims[0], dims[1], dims[2]}, type, 0.02, 7};
    char raw[4400];
    test_generate_raw(dir, ip_field_name(field), &p, raw, sizeof raw);
    snprintf(ibv, size, "%s/%s.b%u.ibv", dir, ip_field_name(field), edge);
    test_brick_raw(raw, ibv, edge, subblock);
    unlink(raw);
}

static unsigned char *read_file(const char *path, uint64_t *size)
{
    FILE *f = fopen(path, "rb");
    REQUIRE(f);
    struct stat st;
    REQUIRE(fstat(fileno(f), &st) == 0);
    *size = (uint64_t)st.st_size;
    unsigned char *bytes = malloc(*size);
    REQUIRE(bytes && fread(bytes, 1, *size, f) == *size);
    fclose(f);
    return bytes;
}

static void write_file(const char *path, const unsigned char *bytes, uint64_t size)
{
    FILE *f = fopen(path, "wb");
    REQUIRE(f && fwrite(bytes, 1, size, f) == size && fclose(f) == 0);
}

/* Called between steps of a progressive run once `after_rays` rays are cast: changes the file
 * under the open store. */
typedef struct midway {
    uint64_t after_rays;
    void (*change)(const char *path, void *user);
    void *user;
    int done;
} midway;

/* Progressive extraction of `path` with `threads` threads, every ray, in doubling batches (as
 * isorender does), the cache holding `budget` bytes; its image into `rgba`. */
static ip_status run_progressive(const subject *s, const char *path, unsigned threads,
                                 uint64_t budget, midway *mid, uint8_t *rgba, ip_error *err)
{
    ip_store *store = NULL;
    ip_cache *cache = NULL;
    ip_engine *engine = NULL;
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.threads = threads;
    ip_status st = ip_store_open(path, &store, err);
    if (st == IP_OK)
        st = ip_cache_create(store, budget, &cache, err);
    if (st == IP_OK)
        st = ip_engine_create(cache, &o, &engine, err);
    if (st == IP_OK)
        st = ip_engine_begin(engine, &s->camera, s->iso, err);
    uint64_t batch = 1, rays = 0;
    while (st == IP_OK && !ip_engine_done(engine)) {
        if (mid && !mid->done && rays >= mid->after_rays) {
            mid->change(path, mid->user);
            mid->done = 1;
        }
        ip_engine_counts c = {0};
        st = ip_engine_step(engine, batch, 0, &c, err);
        rays += c.rays;
        batch *= 2;
    }
    if (st == IP_OK)
        st = ip_raster_mesh(ip_engine_mesh(engine), &s->camera, s->lo, s->hi, NULL, rgba, err);
    ip_engine_destroy(engine);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return st;
}

static ip_status run_full(const subject *s, const char *path, unsigned threads, uint8_t *rgba,
                          ip_error *err)
{
    ip_store *store = NULL;
    ip_cache *cache = NULL;
    ip_mesh mesh;
    ip_mesh_init(&mesh);
    ip_status st = ip_store_open(path, &store, err);
    if (st == IP_OK)
        st = ip_cache_create(store, 1u << 20, &cache, err);
    if (st == IP_OK)
        st = ip_extract_full(cache, s->iso, 0, threads, &mesh, NULL, err);
    if (st == IP_OK)
        st = ip_raster_mesh(&mesh, &s->camera, s->lo, s->hi, NULL, rgba, err);
    ip_mesh_free(&mesh);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return st;
}

static ip_status run_kind(const subject *s, const char *path, int kind, uint8_t *rgba,
                          ip_error *err)
{
    if (kind < 2)
        return run_progressive(s, path, kind + 1, 1u << 20, NULL, rgba, err);
    return run_full(s, path, kind - 1, rgba, err);
}

/* 1 when `message` holds "brick G" not followed by another digit. */
static int names_brick(const char *message, uint64_t g)
{
    char want[40];
    snprintf(want, sizeof want, "brick %llu", (unsigned long long)g);
    for (const char *p = strstr(message, want); p; p = strstr(p + 1, want)) {
        char next = p[strlen(want)];
        if (next < '0' || next > '9')
            return 1;
    }
    return 0;
}

/* Judges one run of a corrupted copy: an error naming the file (and brick `g`, or any brick
 * when g is UINT64_MAX), or the reference image. */
static void judge(tally *t, const char *what, const char *path, uint64_t g, ip_status st,
                  const ip_error *err, const uint8_t *rgba, const uint8_t *reference)
{
    t->runs++;
    if (st != IP_OK) {
        int clear = err->code == st && strstr(err->message, path) &&
                    (g == UINT64_MAX ? strstr(err->message, "brick") != NULL
                                     : names_brick(err->message, g)) &&
                    !strchr(err->message, '\n');
        if (clear) {
            t->errors++;
        } else {
            t->unclear++;
            CHECK_MSG(clear, "%s: status %d with an unclear message: \"%s\"", what, (int)st,
                      err->message);
        }
        return;
    }
    size_t differ = 0;
    for (size_t i = 0; i < (size_t)WIDTH * HEIGHT; i++)
        differ += memcmp(rgba + 4 * i, reference + 4 * i, 4) != 0;
    if (differ == 0) {
        t->identical++;
    } else {
        t->silent++;
        fprintf(stderr, "test_corrupt: SILENT: %s: no error and %zu of %d pixels differ\n", what,
                differ, WIDTH * HEIGHT);
    }
}

static void open_subject(subject *s, const char *name, const char *path, float iso,
                         const char *axis)
{
    ip_error err;
    snprintf(s->name, sizeof s->name, "%s", name);
    snprintf(s->path, sizeof s->path, "%s", path);
    s->iso = iso;
    s->bytes = read_file(path, &s->size);
    REQUIRE(ip__format_parse(s->bytes, s->size, path, 0, &s->layout, &err) == IP_OK);
    ip_layout_world_box(&s->layout, s->lo, s->hi);
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, axis, 30.0, WIDTH, HEIGHT, &s->camera, &err) == IP_OK);
    for (int k = 0; k < 4; k++) {
        s->reference[k] = malloc((size_t)WIDTH * HEIGHT * 4);
        REQUIRE(s->reference[k]);
        ip_status st = run_kind(s, path, k, s->reference[k], &err);
        CHECK_MSG(st == IP_OK, "%s: intact file, %s: %s", name, run_names[k], err.message);
    }
    /* the surface must fill a good part of the picture, or identical images would prove little */
    uint8_t *background = malloc((size_t)WIDTH * HEIGHT * 4);
    ip_mesh empty;
    ip_mesh_init(&empty);
    REQUIRE(background &&
            ip_raster_mesh(&empty, &s->camera, s->lo, s->hi, NULL, background, &err) == IP_OK);
    size_t covered = 0;
    for (size_t i = 0; i < (size_t)WIDTH * HEIGHT; i++)
        covered += memcmp(s->reference[0] + 4 * i, background + 4 * i, 4) != 0;
    free(background);
    printf("test_corrupt: %s: %llu bytes, %llu bricks, %u levels; the surface covers %zu of "
           "%d pixels\n",
           name, (unsigned long long)s->size, (unsigned long long)s->layout.brick_count,
           s->layout.level_count, covered, WIDTH * HEIGHT);
    CHECK_MSG(covered * 10 > (size_t)WIDTH * HEIGHT, "%s: the surface covers only %zu pixels", name,
              covered);
}

static void close_subject(subject *s)
{
    for (int k = 0; k < 4; k++)
        free(s->reference[k]);
    free(s->bytes);
}

/* isoinfo --verify on a copy: every brick read and checked against its summaries, and the
 * octree. @return the first error, IP_OK when the copy passes. */
static ip_status verify_copy(const char *path, ip_error *err)
{
    ip_store *store;
    ip_status st = ip_store_open(path, &store, err);
    if (st != IP_OK)
        return st;
    const ip_layout *l = ip_store_layout(store);
    size_t edge = (size_t)l->brick_edge + 1;
    void *dst = malloc(edge * edge * edge * ip_type_size(l->type));
    void *work = malloc(ip_store_read_work_size(store));
    REQUIRE(dst && work);
    for (uint64_t g = 0; g < l->brick_count && st == IP_OK; g++)
        st = ip_store_verify_brick(store, g, dst, work, err);
    if (st == IP_OK)
        st = ip_store_verify_octree(store, err);
    free(dst);
    free(work);
    ip_store_close(store);
    return st;
}

/* The copy at `path` (already written) through verification and the four runs. `g` is the
 * brick an error must name (UINT64_MAX: any brick). */
static void try_copy(const subject *s, const char *path, uint64_t g, const char *what,
                     tally runs[4], tally *verify)
{
    ip_error err;
    char label[512];
    uint8_t *rgba = malloc((size_t)WIDTH * HEIGHT * 4);
    REQUIRE(rgba);
    ip_status st = verify_copy(path, &err);
    snprintf(label, sizeof label, "%s: %s: verification", s->name, what);
    verify->runs++;
    if (st == IP_OK) {
        verify->silent++;
        CHECK_MSG(st != IP_OK, "%s accepts the corrupted file", label);
    } else if (strstr(err.message, path) && (g == UINT64_MAX || names_brick(err.message, g))) {
        verify->errors++;
    } else {
        verify->unclear++;
        CHECK_MSG(0, "%s: unclear message \"%s\"", label, err.message);
    }
    for (int k = 0; k < 4; k++) {
        ip_error_clear(&err);
        memset(rgba, 0, (size_t)WIDTH * HEIGHT * 4);
        st = run_kind(s, path, k, rgba, &err);
        snprintf(label, sizeof label, "%s: %s: %s", s->name, what, run_names[k]);
        judge(&runs[k], label, path, g, st, &err, rgba, s->reference[k]);
    }
    free(rgba);
}

static void report(const char *name, const char *kind, int copies, const tally runs[4],
                   const tally *verify)
{
    printf("test_corrupt: %s, %s: %d copies; verification %d errors, %d accepted\n", name, kind,
           copies, verify->errors, verify->silent);
    for (int k = 0; k < 4; k++) {
        printf("test_corrupt:   %-22s %3d runs: %3d errors, %3d identical, %d SILENT, %d unclear\n",
               run_names[k], runs[k].runs, runs[k].errors, runs[k].identical, runs[k].silent,
               runs[k].unclear);
        CHECK_MSG(runs[k].silent == 0,
                  "%s, %s, %s: %d of %d runs gave a different image "
                  "without an error",
                  name, kind, run_names[k], runs[k].silent, runs[k].runs);
    }
}

/* A bit flipped in the payload of every payload brick (or a spread of MAX_COPIES of them). */
static void check_payload_flips(const subject *s, const char *dir)
{
    ip_summary_offsets so;
    ip__summary_offsets_of(&s->layout, &so);
    uint64_t *bricks = malloc(s->layout.brick_count * sizeof *bricks), count = 0;
    REQUIRE(bricks);
    for (uint64_t g = 0; g < s->layout.brick_count; g++) {
        ip_brick_entry e;
        ip__format_entry_decode(
            s->bytes + s->layout.summary_offset + so.directory + g * IP_DIRECTORY_ENTRY_SIZE, &e);
        if (e.stored_size > 0)
            bricks[count++] = g;
    }
    REQUIRE(count > 0);
    uint64_t step = count > MAX_COPIES ? (count + MAX_COPIES - 1) / MAX_COPIES : 1;
    tally runs[4] = {{0}}, verify = {0};
    int copies = 0;
    char path[4400], what[160];
    snprintf(path, sizeof path, "%s/%s.flip.ibv", dir, s->name);
    unsigned char *copy = malloc(s->size);
    REQUIRE(copy);
    for (uint64_t i = 0; i < count; i += step) {
        uint64_t g = bricks[i];
        ip_brick_entry e;
        ip__format_entry_decode(
            s->bytes + s->layout.summary_offset + so.directory + g * IP_DIRECTORY_ENTRY_SIZE, &e);
        /* a different spot and bit in each brick: first bytes, middle, last */
        uint64_t byte = e.offset + (e.stored_size - 1) * (i % 5) / 4;
        memcpy(copy, s->bytes, s->size);
        copy[byte] ^= (unsigned char)(1u << (i % 8));
        write_file(path, copy, s->size);
        snprintf(what, sizeof what, "brick %llu, bit %llu of byte %llu flipped",
                 (unsigned long long)g, (unsigned long long)(i % 8), (unsigned long long)byte);
        try_copy(s, path, g, what, runs, &verify);
        copies++;
    }
    report(s->name, "one bit flipped in a payload", copies, runs, &verify);
    CHECK_EQ(verify.errors, copies);
    unlink(path);
    free(copy);
    free(bricks);
}

/* A zeroed 4 KiB page of the data section (pages that were zero already are skipped). */
static void check_zero_pages(const subject *s, const char *dir)
{
    uint64_t data_end = s->layout.data_offset + s->layout.data_size;
    uint64_t pages = (data_end + PAGE - 1) / PAGE;
    uint64_t step = pages > MAX_COPIES ? (pages + MAX_COPIES - 1) / MAX_COPIES : 1;
    tally runs[4] = {{0}}, verify = {0};
    int copies = 0;
    char path[4400], what[160];
    snprintf(path, sizeof path, "%s/%s.zero.ibv", dir, s->name);
    unsigned char *copy = malloc(s->size);
    REQUIRE(copy);
    for (uint64_t page = 0; page < pages; page += step) {
        uint64_t start = page * PAGE < IP_HEADER_SIZE ? IP_HEADER_SIZE : page * PAGE;
        uint64_t end = (page + 1) * PAGE < data_end ? (page + 1) * PAGE : data_end;
        memcpy(copy, s->bytes, s->size);
        int changed = 0;
        for (uint64_t b = start; b < end; b++) {
            changed |= copy[b] != 0;
            copy[b] = 0;
        }
        if (!changed)
            continue;
        write_file(path, copy, s->size);
        snprintf(what, sizeof what, "bytes %llu-%llu zeroed", (unsigned long long)start,
                 (unsigned long long)end);
        try_copy(s, path, UINT64_MAX, what, runs, &verify);
        copies++;
    }
    report(s->name, "a 4 KiB page of the data section zeroed", copies, runs, &verify);
    CHECK_GT(copies, 0);
    CHECK_EQ(verify.errors, copies);
    unlink(path);
    free(copy);
}

/* A store that reads a file truncated under it must not die of SIGBUS: if it does, say so
 * before dying, so that the failure is plain in the log. */
static void on_sigbus(int sig)
{
    static const char message[] =
        "test_corrupt: SIGBUS: the engine touched bytes past the end of a truncated file\n";
    (void)sig;
    ssize_t ignored = write(2, message, sizeof message - 1);
    (void)ignored;
    _exit(1);
}

static void truncate_to_half(const char *path, void *user)
{
    const subject *s = user;
    REQUIRE(truncate(path, (off_t)(s->size / 2)) == 0);
}

/* Zeroes 32 bytes in the middle of every payload in place (same size, same file). */
static void overwrite_payloads(const char *path, void *user)
{
    const subject *s = user;
    ip_summary_offsets so;
    ip__summary_offsets_of(&s->layout, &so);
    int fd = open(path, O_WRONLY);
    REQUIRE(fd >= 0);
    static const unsigned char zeros[32];
    for (uint64_t g = 0; g < s->layout.brick_count; g++) {
        ip_brick_entry e;
        ip__format_entry_decode(
            s->bytes + s->layout.summary_offset + so.directory + g * IP_DIRECTORY_ENTRY_SIZE, &e);
        if (e.stored_size == 0)
            continue;
        uint64_t at = e.offset + e.stored_size / 2, n = e.stored_size - e.stored_size / 2;
        if (n > sizeof zeros)
            n = sizeof zeros;
        /* make sure the bytes change: zeros over zeros would prove nothing */
        int nonzero = 0;
        for (uint64_t b = 0; b < n; b++)
            nonzero |= s->bytes[at + b] != 0;
        unsigned char ones[32];
        memset(ones, 0xa5, sizeof ones);
        REQUIRE(pwrite(fd, nonzero ? zeros : ones, n, (off_t)at) == (ssize_t)n);
    }
    REQUIRE(close(fd) == 0);
}

/* Files that change while a render reads them, with 1 and 2 threads. */
static void check_changing(const subject *s, const char *dir)
{
    struct sigaction sa, old;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigbus;
    sigemptyset(&sa.sa_mask);
    REQUIRE(sigaction(SIGBUS, &sa, &old) == 0);
    char path[4400];
    uint8_t *rgba = malloc((size_t)WIDTH * HEIGHT * 4);
    REQUIRE(rgba);
    for (unsigned threads = 1; threads <= 2; threads++) {
        /* truncated to half after the first rays: the cache holds one brick at most, so the
         * rest of the render must read the file again, and past its new end */
        snprintf(path, sizeof path, "%s/%s.shrinking.ibv", dir, s->name);
        write_file(path, s->bytes, s->size);
        midway mid = {64, truncate_to_half, (void *)s, 0};
        ip_error err;
        ip_error_clear(&err);
        ip_status st = run_progressive(s, path, threads, 4096, &mid, rgba, &err);
        CHECK(mid.done);
        int says_changed = strstr(err.message, "truncat") || strstr(err.message, "shorter") ||
                           strstr(err.message, "shrank") || strstr(err.message, "changed") ||
                           strstr(err.message, "rewritten");
        printf("test_corrupt: %s, truncated to half mid-render, %u thread%s: status %d \"%s\"\n",
               s->name, threads, threads > 1 ? "s" : "", (int)st, err.message);
        CHECK_MSG(st != IP_OK, "%s: truncated mid-render, %u threads: no error", s->name, threads);
        CHECK_MSG(st == IP_OK || (err.code == st && strstr(err.message, path) && says_changed),
                  "%s: truncated mid-render: the message \"%s\" should name the file and say "
                  "it is shorter or changed",
                  s->name, err.message);
        unlink(path);

        /* payload bytes overwritten in place after the first rays */
        snprintf(path, sizeof path, "%s/%s.rewritten.ibv", dir, s->name);
        write_file(path, s->bytes, s->size);
        midway rewrite = {64, overwrite_payloads, (void *)s, 0};
        ip_error_clear(&err);
        st = run_progressive(s, path, threads, 4096, &rewrite, rgba, &err);
        CHECK(rewrite.done);
        printf("test_corrupt: %s, payloads overwritten mid-render, %u thread%s: status %d "
               "\"%s\"\n",
               s->name, threads, threads > 1 ? "s" : "", (int)st, err.message);
        tally t = {0};
        char label[256];
        snprintf(label, sizeof label, "%s: payloads overwritten mid-render, %u threads", s->name,
                 threads);
        judge(&t, label, path, UINT64_MAX, st, &err, rgba, s->reference[threads - 1]);
        CHECK_MSG(t.silent == 0, "%s: a different image without an error", label);
        CHECK_MSG(st == IP_OK || st == IP_ERR_CHECKSUM || st == IP_ERR_CORRUPT,
                  "%s: status %d, expected a checksum error", label, (int)st);
        unlink(path);
    }
    free(rgba);
    REQUIRE(sigaction(SIGBUS, &old, NULL) == 0);
}

/* The volumes, each opened as a subject (made and read once) by the first case that uses it and
 * closed when a case uses the other one, or after the last case. */
static const struct {
    const char *name;
    ip_field field;
    uint32_t dims[3];
    ip_type type;
    uint32_t edge, subblock;
    float iso;
    const char *axis;
} volumes[] = {
    /* many small LZ4 bricks over four pyramid levels; the surface fills the volume */
    {"gyroid-u16", IP_FIELD_GYROID, {34, 37, 29}, IP_UINT16, 8, 2, 2047.5f, "-y"},
    /* float32 samples, raw and LZ4 bricks, constant bricks around the sphere */
    {"sphere-f32", IP_FIELD_SPHERE, {30, 27, 33}, IP_FLOAT32, 4, 2, 0.1f, "+x"},
};
static const char *scratch_dir;
static subject the_subject;
static int subject_volume = -1; /* the volume the_subject holds, or -1 */

static void close_the_subject(void)
{
    if (subject_volume >= 0)
        close_subject(&the_subject);
    subject_volume = -1;
}

static const subject *subject_of(int v)
{
    if (subject_volume != v) {
        close_the_subject();
        char ibv[4200];
        make_volume(scratch_dir, volumes[v].field, volumes[v].dims, volumes[v].type,
                    volumes[v].edge, volumes[v].subblock, ibv, sizeof ibv);
        memset(&the_subject, 0, sizeof the_subject);
        open_subject(&the_subject, volumes[v].name, ibv, volumes[v].iso, volumes[v].axis);
        subject_volume = v;
    }
    return &the_subject;
}

static void gyroid_payload_flips(void)
{
    check_payload_flips(subject_of(0), scratch_dir);
}
static void gyroid_zero_pages(void)
{
    check_zero_pages(subject_of(0), scratch_dir);
}
static void gyroid_changing(void)
{
    check_changing(subject_of(0), scratch_dir);
}
static void sphere_payload_flips(void)
{
    check_payload_flips(subject_of(1), scratch_dir);
}
static void sphere_zero_pages(void)
{
    check_zero_pages(subject_of(1), scratch_dir);
}
static void sphere_changing(void)
{
    check_changing(subject_of(1), scratch_dir);
}

static const test_case cases[] = {
    {"check_payload_flips:gyroid-u16", gyroid_payload_flips},
    {"check_zero_pages:gyroid-u16", gyroid_zero_pages},
    {"check_changing:gyroid-u16", gyroid_changing},
    {"check_payload_flips:sphere-f32", sphere_payload_flips},
    {"check_zero_pages:sphere-f32", sphere_zero_pages},
    {"check_changing:sphere-f32", sphere_changing},
};

static void make_scratch_dir(void)
{
    scratch_dir = test_tmp_dir("test_corrupt");
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_corrupt", make_scratch_dir, close_the_subject);
}
