/* The progressive engine: ray order, seeding, propagation, step budgets and cancellation. */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/engine.h"
#include "isoprop/ray_order.h"
#include "propagate.h"
#include "seed.h"

struct ip_engine {
    ip_cache *cache;
    ip_engine_options options;
    ip_sampler sampler;
    ip_visited visited;
    ip_mesh mesh;
    ip_camera camera;
    ip_camera_basis basis;
    float iso;
    int begun;
    ip_ray_order order;
    ip_seeder seeder;
    ip_propagator propagator;
    ip_engine_counts totals;
    atomic_int cancel;
};

void ip_engine_options_default(ip_engine_options *o)
{
    o->cutoff_degrees = IP_DEFAULT_CUTOFF_DEGREES;
    o->foldback_degrees = IP_DEFAULT_FOLDBACK_DEGREES;
}

ip_status ip_engine_create(ip_cache *cache, const ip_engine_options *options, ip_engine **out,
                           ip_error *err)
{
    if (!(options->cutoff_degrees > 0 && options->cutoff_degrees <= 180) ||
        !(options->foldback_degrees >= 0 && options->foldback_degrees <= 180))
        return ip_fail(err, IP_ERR_ARGUMENT, "cut-off %g and fold-back %g must be in degrees, "
                       "0 < cut-off <= 180, 0 <= fold-back <= 180",
                       options->cutoff_degrees, options->foldback_degrees);
    ip_engine *e = calloc(1, sizeof *e);
    if (!e)
        return ip_fail(err, IP_ERR_NOMEM, "out of memory");
    e->cache = cache;
    e->options = *options;
    atomic_init(&e->cancel, 0);
    ip_mesh_init(&e->mesh);
    const ip_layout *l = ip_store_layout(ip_cache_store(cache));
    if (ip_sampler_init(&e->sampler, cache, 0) != IP_OK ||
        ip_visited_init(&e->visited, l) != IP_OK) {
        ip_engine_destroy(e);
        return ip_fail(err, IP_ERR_NOMEM, "out of memory");
    }
    *out = e;
    return IP_OK;
}

void ip_engine_destroy(ip_engine *e)
{
    if (!e)
        return;
    ip_propagator_free(&e->propagator);
    ip_sampler_free(&e->sampler);
    ip_visited_free(&e->visited);
    ip_mesh_free(&e->mesh);
    free(e);
}

ip_status ip_engine_begin(ip_engine *e, const ip_camera *camera, float iso, ip_error *err)
{
    ip_status st = ip_camera_check(camera, err);
    if (st != IP_OK)
        return st;
    if (!isfinite(iso))
        return ip_fail(err, IP_ERR_ARGUMENT, "the isovalue must be finite");
    ip_sampler_release(&e->sampler);
    ip_visited_clear(&e->visited);
    ip_mesh_clear(&e->mesh);
    ip_propagator_free(&e->propagator);
    e->camera = *camera;
    ip_camera_basis_of(&e->camera, &e->basis);
    e->iso = iso;
    memset(&e->totals, 0, sizeof e->totals);
    ip_ray_order_init(&e->order, camera->width, camera->height);
    ip_seeder_init(&e->seeder, &e->sampler, iso);
    e->sampler.status = IP_OK;
    if (ip_propagator_init(&e->propagator, &e->sampler, &e->visited, &e->mesh, &e->camera, iso,
                           &e->options) != IP_OK)
        return ip_fail(err, IP_ERR_NOMEM, "out of memory");
    atomic_store(&e->cancel, 0);
    e->begun = 1;
    return IP_OK;
}

void ip_engine_cancel(ip_engine *e)
{
    atomic_store(&e->cancel, 1);
}

int ip_engine_done(const ip_engine *e)
{
    return e->begun && ip_ray_order_emitted(&e->order) == ip_ray_order_count(&e->order);
}

static void add_counts(ip_engine_counts *to, const ip_engine_counts *from)
{
    to->rays += from->rays;
    to->seeds += from->seeds;
    to->cells += from->cells;
    to->triangles += from->triangles;
    to->intersection_seconds += from->intersection_seconds;
    to->propagation_seconds += from->propagation_seconds;
    to->extraction_seconds += from->extraction_seconds;
    to->rendering_seconds += from->rendering_seconds;
}

/* Casts the ray of pixel (x, y), seeding and propagating. */
static ip_status cast_ray(ip_engine *e, uint32_t x, uint32_t y, ip_engine_counts *c)
{
    double dir[3];
    uint32_t seed[3];
    ip_camera_pixel_ray(&e->basis, &e->camera, x + 0.5, y + 0.5, dir);
    double t0 = ip_now_seconds();
    int found = ip_seed_find(&e->seeder, e->camera.eye, dir, seed);
    c->intersection_seconds += ip_now_seconds() - t0;
    c->rays++;
    if (found < 0)
        return e->sampler.status;
    if (found == 0)
        return IP_OK;
    int was = ip_visited_mark(&e->visited, 0, seed);
    if (was < 0)
        return IP_ERR_NOMEM;
    if (was)
        return IP_OK;
    c->seeds++;
    return ip_propagate(&e->propagator, seed, dir, c);
}

ip_status ip_engine_step(ip_engine *e, uint64_t max_rays, double max_seconds,
                         ip_engine_counts *counts, ip_error *err)
{
    ip_engine_counts c;
    memset(&c, 0, sizeof c);
    if (!e->begun)
        return ip_fail(err, IP_ERR_ARGUMENT, "ip_engine_step() before ip_engine_begin()");
    double start = ip_now_seconds();
    ip_status st = IP_OK;
    uint32_t x, y;
    for (uint64_t i = 0; max_rays == 0 || i < max_rays; i++) {
        if (atomic_load_explicit(&e->cancel, memory_order_relaxed)) {
            st = ip_fail(err, IP_ERR_CANCELLED, "extraction cancelled");
            break;
        }
        if (max_seconds > 0 && (i & 15) == 0 && i > 0 && ip_now_seconds() - start >= max_seconds)
            break;
        if (!ip_ray_order_next(&e->order, &x, &y))
            break;
        st = cast_ray(e, x, y, &c);
        if (st != IP_OK) {
            if (st == IP_ERR_NOMEM)
                ip_fail(err, st, "out of memory");
            else if (err)
                *err = e->sampler.error;
            break;
        }
    }
    ip_sampler_release(&e->sampler); /* let the cache evict freely between steps */
    add_counts(&e->totals, &c);
    if (counts)
        *counts = c;
    return st;
}

const ip_mesh *ip_engine_mesh(const ip_engine *e)
{
    return &e->mesh;
}

void ip_engine_totals(const ip_engine *e, ip_engine_counts *counts)
{
    *counts = e->totals;
}

void ip_engine_add_rendering_time(ip_engine *e, double seconds)
{
    e->totals.rendering_seconds += seconds;
}
