/* SPDX-License-Identifier: BSD-3-Clause */
/* libFuzzer harness: the store, the cache and the engine on mutated brick files, not only the
 * parsers. Whatever the bytes, opening, progressive extraction, full extraction, rasterizing
 * the result and isoinfo-style verification must never crash, hang, leak or trip ASan/UBSan;
 * any error status is fine (it must come with a one-line message).
 *
 * Input layout: 4 control bytes, then the brick file.
 *   byte 0  bit 0: "hostile" mode: before opening, recompute every checksum the format has
 *           (each payload's in its directory entry, the summary section's and the header's;
 *           see docs/format.md) so that a mutated file passes them and the decoder and the
 *           engine see structurally valid but semantically hostile data (summaries that
 *           disagree with the samples, NaN and infinite float32 samples, huge values);
 *           bit 1: adaptive resolution (lod) on; bits 2-3: pixel error 1 + value;
 *           bits 4-7: cache budget in 4 KiB units (0: 1 byte, so every pin goes over budget)
 *   byte 1  view: the axis side (value % 6) of the camera fitted to the volume, and with
 *           value >= 192 a camera placed inside the volume instead
 *   byte 2  isovalue: value_min + (value_max - value_min) * (byte / 255) of the file's range
 *   byte 3  pyramid level of the full extraction (modulo the level count)
 * The seeds in corpus_fuzz_engine/ are small valid brick files (made by isogen and isobrick)
 * behind such control bytes, some in hostile mode; e.g. sphere_9_u8_b4.seed is
 *     printf '\x00\x03\x80\x00' >S; isogen sphere --dims 9x9x9 --type uint8 -o ./
 *     isobrick sphere_9x9x9_uint8.raw -o s.ibv --brick-size 4 --subblock-size 2; cat s.ibv >>S
 * (the others: gyroid, marschner-lobb, shepp-logan; uint8 to float32; --noise for raw
 * bricks; brick edges 2 to 8). crash_*.seed are reproducers of findings, named for what they
 * show (made with tests/helpers/corrupt: `corrupt apply IN OUT set:OFFSET:HEX --rehash`).
 *
 * The file is handed to the store through a memfd (/proc/self/fd/N), so the store's real
 * open and read paths run, with nothing written to disk. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "isoprop/engine.h"
#include "format.h"
#include "isoprop/render.h"
#include "isoprop/store.h"
#include "rehash.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CONTROL 4
#define WIDTH 16
#define HEIGHT 12
#define MAX_VERIFIED_BRICKS 4096 /* keeps one input fast */

/* Every error must say something, on one line. */
static void check_error(ip_status st, const ip_error *err)
{
    if (st == IP_OK)
        return;
    if (err->message[0] == '\0' || !memchr(err->message, '\0', sizeof err->message) ||
        strchr(err->message, '\n')) {
        fprintf(stderr, "status %d with message '%.1023s'\n", (int)st, err->message);
        abort();
    }
}

static void run_engine(ip_cache *cache, const ip_layout *l, const uint8_t control[CONTROL])
{
    ip_error err;
    double lo[3], hi[3];
    ip_layout_world_box(l, lo, hi);
    static const char *const axes[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    ip_camera cam;
    if (ip_camera_fit_axis(lo, hi, axes[control[1] % 6], 30.0, WIDTH, HEIGHT, &cam, &err) != IP_OK)
        return;
    if (control[1] >= 192) { /* inside the volume, looking along a diagonal */
        for (int a = 0; a < 3; a++) {
            cam.eye[a] = hi[a] * (0.25 + 0.125 * ((control[1] >> a) & 1));
            cam.target[a] = hi[a];
        }
        cam.up[0] = 0, cam.up[1] = 0, cam.up[2] = 1;
        if (ip_camera_check(&cam, &err) != IP_OK)
            return;
    }
    float iso = l->value_min + (l->value_max - l->value_min) * ((float)control[2] / 255.0f);

    ip_engine_options o;
    ip_engine_options_default(&o);
    o.threads = 1;
    o.lod = (control[0] >> 1) & 1;
    o.pixel_error = 1 + ((control[0] >> 2) & 3);
    ip_engine *engine;
    if (ip_engine_create(cache, &o, &engine, &err) != IP_OK)
        return;
    ip_status st = ip_engine_begin(engine, &cam, iso, &err);
    check_error(st, &err);
    for (uint64_t batch = 1; st == IP_OK && !ip_engine_done(engine); batch *= 2)
        check_error(st = ip_engine_step(engine, batch, 0, NULL, &err), &err);
    /* the mesh so far, whatever happened: rasterizing it must be safe too */
    check_error(ip_raster_mesh(ip_engine_mesh(engine), &cam, lo, hi, NULL, NULL, &err), &err);
    ip_engine_destroy(engine);

    ip_mesh mesh;
    ip_mesh_init(&mesh);
    check_error(ip_extract_full(cache, iso, control[3] % l->level_count, 1, &mesh, NULL, &err),
                &err);
    uint8_t rgba[WIDTH * HEIGHT * 4];
    check_error(ip_raster_mesh(&mesh, &cam, lo, hi, NULL, rgba, &err), &err);
    ip_mesh_free(&mesh);
}

/* isoinfo --verify: every brick against its summaries, then the octree. */
static void verify(const ip_store *store, const ip_layout *l)
{
    ip_error err;
    size_t edge = (size_t)l->brick_edge + 1;
    void *dst = malloc(edge * edge * edge * ip_type_size(l->type));
    void *work = malloc(ip_store_read_work_size(store));
    if (!dst || !work)
        abort();
    for (uint64_t g = 0; g < l->brick_count && g < MAX_VERIFIED_BRICKS; g++)
        check_error(ip_store_verify_brick(store, g, dst, work, &err), &err);
    check_error(ip_store_verify_octree(store, &err), &err);
    free(dst);
    free(work);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < CONTROL)
        return 0;
    uint8_t control[CONTROL];
    memcpy(control, data, CONTROL);
    size_t file_size = size - CONTROL;
    unsigned char *file = malloc(file_size + 1);
    if (!file)
        return 0;
    memcpy(file, data + CONTROL, file_size);
    if (control[0] & 1)
        test_rehash(file, file_size);

    int fd = memfd_create("fuzz_engine.ibv", MFD_CLOEXEC);
    if (fd < 0) {
        perror("fuzz_engine: memfd_create");
        abort();
    }
    size_t done = 0;
    while (done < file_size) {
        ssize_t n = write(fd, file + done, file_size - done);
        if (n <= 0) {
            perror("fuzz_engine: write");
            abort();
        }
        done += (size_t)n;
    }
    free(file);
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);

    ip_store *store;
    ip_error err;
    ip_status st = ip_store_open(path, &store, &err);
    check_error(st, &err);
    if (st == IP_OK) {
        const ip_layout *l = ip_store_layout(store);
        uint64_t budget = (uint64_t)(control[0] >> 4) * 4096;
        ip_cache *cache;
        if (ip_cache_create(store, budget ? budget : 1, &cache, &err) == IP_OK) {
            run_engine(cache, l, control);
            ip_cache_destroy(cache);
        }
        verify(store, l);
        ip_store_close(store);
    }
    close(fd);
    return 0;
}
