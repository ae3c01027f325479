/* SPDX-License-Identifier: BSD-3-Clause */
/* Allocation failures through the public calls: a small whole run (describe, brick, open,
 * cache, engine steps to the exact image, full extraction, weld, write) is repeated with the
 * library's Nth allocation failing, for every N until a run makes fewer allocations than N.
 * Each call must then fail with a clear error (a status and a one-line message) or succeed,
 * and everything made before must be released: the sanitizer build's leak checker sees every
 * run. The library's own calls to malloc, calloc, realloc and posix_memalign are wrapped at
 * link time (-Wl,--wrap), so the C library's and the test's own allocations are not counted. */
#include <stdlib.h>

#include "check.h"
#include "isoprop/isoprop.h"

void *__real_malloc(size_t size);
void *__real_calloc(size_t count, size_t size);
void *__real_realloc(void *p, size_t size);
int __real_posix_memalign(void **out, size_t alignment, size_t size);
void *__wrap_malloc(size_t size);
void *__wrap_calloc(size_t count, size_t size);
void *__wrap_realloc(void *p, size_t size);
int __wrap_posix_memalign(void **out, size_t alignment, size_t size);

static long fail_at;   /* the allocation to fail (1-based); 0: none */
static long counted;   /* allocations counted since arming */
static int failed_one; /* the armed allocation was reached and failed */

/* 1 when this allocation is the one to fail. Single-threaded runs: plain counters. */
static int fail_now(void)
{
    if (fail_at == 0)
        return 0;
    if (++counted != fail_at)
        return 0;
    failed_one = 1;
    return 1;
}

void *__wrap_malloc(size_t size)
{
    return fail_now() ? NULL : __real_malloc(size);
}

void *__wrap_calloc(size_t count, size_t size)
{
    return fail_now() ? NULL : __real_calloc(count, size);
}

void *__wrap_realloc(void *p, size_t size)
{
    return fail_now() ? NULL : __real_realloc(p, size);
}

int __wrap_posix_memalign(void **out, size_t alignment, size_t size)
{
    return fail_now() ? 12 /* ENOMEM */ : __real_posix_memalign(out, alignment, size);
}

/* A failed call: a negative status and a one-line message. */
static void check_error(ip_status st, const ip_error *err, const char *call)
{
    CHECK_MSG(st < 0, "%s: status %d", call, (int)st);
    CHECK_MSG(err->message[0] != '\0' && strchr(err->message, '\n') == NULL, "%s: message \"%s\"",
              call, err->message);
}

/* One whole run on `raw` into `ibv`; returns 1 when every call succeeded. */
static int one_run(const char *raw, const char *ibv, const char *ply)
{
    ip_error err;
    ip_error_clear(&err);
    ip_input_desc desc;
    ip_status st = ip_input_describe(raw, NULL, &desc, &err);
    if (st != IP_OK)
        return check_error(st, &err, "describe"), 0;
    ip_bricker_options options;
    ip_bricker_options_default(&options);
    options.brick_edge = 8;
    options.threads = 1;
    options.force = 1;
    if ((st = ip_bricker_run(&desc, ibv, &options, NULL, &err)) != IP_OK)
        return check_error(st, &err, "brick"), 0;
    ip_store *store = NULL;
    ip_cache *cache = NULL;
    ip_engine *engine = NULL;
    ip_mesh full;
    ip_mesh_init(&full);
    ip_indexed_mesh welded;
    ip_indexed_mesh_init(&welded);
    int ok = 0;
    const char *call = "open";
    if ((st = ip_store_open(ibv, &store, &err)) != IP_OK)
        goto done;
    call = "cache";
    if ((st = ip_cache_create(store, 8u << 20, &cache, &err)) != IP_OK)
        goto done;
    ip_engine_options eo;
    ip_engine_options_default(&eo);
    eo.threads = 1;
    call = "engine";
    if ((st = ip_engine_create(cache, &eo, &engine, &err)) != IP_OK)
        goto done;
    double lo[3], hi[3];
    ip_layout_world_box(ip_store_layout(store), lo, hi);
    ip_camera camera;
    call = "camera";
    if ((st = ip_camera_fit_axis(lo, hi, "-y", 30.0, 48, 36, &camera, &err)) != IP_OK)
        goto done;
    call = "begin";
    if ((st = ip_engine_begin(engine, &camera, 100.5f, &err)) != IP_OK)
        goto done;
    call = "step";
    while (!ip_engine_done(engine))
        if ((st = ip_engine_step(engine, 200, 0, NULL, &err)) != IP_OK)
            goto done;
    call = "full extraction";
    if ((st = ip_extract_full(cache, 100.5f, 0, 1, &full, NULL, &err)) != IP_OK)
        goto done;
    call = "weld";
    if ((st = ip_mesh_weld(&full, &welded)) != IP_OK) {
        snprintf(err.message, sizeof err.message, "weld: %s", ip_status_message(st));
        goto done;
    }
    call = "write";
    if ((st = ip_indexed_mesh_write(&welded, ply, 1, &err)) != IP_OK)
        goto done;
    ok = 1;
done:
    if (!ok)
        check_error(st, &err, call);
    ip_indexed_mesh_free(&welded);
    ip_mesh_free(&full);
    ip_engine_destroy(engine);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return ok;
}

static void check_every_allocation(void)
{
    const char *dir = test_tmp_dir("test_alloc_faults");
    char raw[4200], ibv[4200], ply[4200];
    snprintf(raw, sizeof raw, "%s/shepp-logan_20x18x17_uint8.raw", dir);
    snprintf(ibv, sizeof ibv, "%s/s.ibv", dir);
    snprintf(ply, sizeof ply, "%s/s.ply", dir);
    ip_gen_params params = {0};
    params.field = IP_FIELD_SHEPP_LOGAN;
    params.dims[0] = 20;
    params.dims[1] = 18;
    params.dims[2] = 17;
    params.type = IP_UINT8;
    ip_error err;
    REQUIRE(ip_generate_write(&params, raw, 1, &err) == IP_OK);
    REQUIRE(one_run(raw, ibv, ply)); /* unarmed: every call succeeds */
    long runs = 0, failures_seen = 0;
    for (long n = 1; n < 1000000; n++) {
        fail_at = n;
        counted = 0;
        failed_one = 0;
        int ok = one_run(raw, ibv, ply);
        fail_at = 0;
        runs++;
        if (!failed_one) { /* the run made fewer than n allocations: every one has failed once */
            CHECK(ok);
            break;
        }
        failures_seen += !ok;
    }
    printf("test_alloc_faults: %ld runs, each allocation of the run failed once; %ld runs failed "
           "cleanly, the others absorbed the failure\n",
           runs, failures_seen);
    CHECK_GT(runs, 10);
}

int main(int argc, char **argv)
{
    static const test_case cases[] = {TEST_CASE(check_every_allocation)};
    return RUN_CASES(argc, argv, cases, "test_alloc_faults");
}
