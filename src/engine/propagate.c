/* SPDX-License-Identifier: BSD-3-Clause */
/* Breadth-first propagation of the isosurface from a seed, within the cut-off angle, stopped
 * where the surface folds back and outside the view frustum. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "lod.h"
#include "propagate.h"
#include "vec3.h"

#define DEG (3.14159265358979323846 / 180.0)
#define TIMING_STRIDE 16    /* extractions per timed extraction */
#define MIN_TEST_PIXELS 2.0 /* the smallest box (projected diagonal) tested for occlusion */
#define MAX_TEST_SHIFT 3    /* ...grown to at most 8 cells a side */
#define SHARE_STRIDE 8      /* extractions between offers of cells to idle workers */

ip_status ip__propagator_init(ip_propagator *p, ip_sampler *sampler, ip_visited *visited,
                              ip_mesh *mesh, const ip_camera *camera, float iso,
                              const ip_engine_options *options, double near_distance,
                              double far_distance, ip_coverage *coverage)
{
    memset(p, 0, sizeof *p);
    p->sampler = sampler;
    p->visited = visited;
    p->out = (ip_cell_output){mesh, coverage, coverage && options->cull, options->reuse};
    p->camera = camera;
    p->window[0] = p->window[1] = 0;
    p->window[2] = camera->width;
    p->window[3] = camera->height;
    ip_camera_basis_of(camera, &p->basis);
    p->iso = iso;
    p->cutoff_versine = 1.0 - cos(options->cutoff_degrees * DEG);
    p->cos_foldback = cos(options->foldback_degrees * DEG);
    p->sin_foldback = sin(options->foldback_degrees * DEG);
    p->clip = (ip_clip){options->clip, options->clip_count};
    p->pixel_scale = 0.5 * camera->height / p->basis.tan_half_y;
    ip__image_axes_of(&p->basis, camera->width, camera->height, &p->axes);
    p->near_distance = near_distance;
    p->far_distance = far_distance;
    ip__depth_queue_init(&p->queue);
    return IP_OK;
}

void ip__propagator_free(ip_propagator *p)
{
    ip__depth_queue_free(&p->queue);
}

int ip__extract_cell(ip_sampler *s, const ip_cell_output *out, const uint32_t cell[3], float iso,
                     unsigned *mc_case, uint64_t *culled, ip_status *st)
{
    float values[8];
    if (ip__sampler_cell_case(s, cell, iso, values, mc_case) < 0) {
        *st = s->status;
        return -1;
    }
    if (*mc_case == 0 || *mc_case == 255)
        return 0;
    /* The vertices first: they are recorded in the coverage, and with culling the triangles
     * drawn at no pixel centre dropped, before the normals (the gradients) are worked out. */
    float lo[3], hi[3], points[12][3], normals[12][3];
    ip__sampler_cell_box(s, cell, lo, hi);
    ip__mc_cell_edge_points(values, *mc_case, iso, lo, hi, points);
    const int8_t *row = s->mc_rows[*mc_case];
    int n = ip__mc_triangle_count[*mc_case];
    float pos[9 * IP_MC_MAX_TRIANGLES];
    int16_t nor[9 * IP_MC_MAX_TRIANGLES];
    uint64_t ids[IP_MC_MAX_TRIANGLES];
    uint32_t shows =
        out->coverage
            ? ip__coverage_add_indexed(out->coverage, (const float(*)[3])points, row, (unsigned)n)
            : 0;
    if (!out->cull || (out->whole_cells && (shows & ((1u << n) - 1))))
        shows = ~0u;
    if (!(shows & ((1u << n) - 1))) {
        *culled += (uint64_t)n;
        return 0;
    }
    if (ip__sampler_cell_normals(s, cell, values, *mc_case, iso, lo, hi, normals) < 0) {
        *st = s->status;
        return -1;
    }
    const ip_level_layout *lv = &s->layout->levels[s->level];
    uint64_t linear =
        cell[0] + (uint64_t)(lv->dims[0] - 1) * (cell[1] + (uint64_t)(lv->dims[1] - 1) * cell[2]);
    int kept = 0;
    for (int t = 0; t < n; t++) {
        if (!(shows >> t & 1))
            continue; /* drawn at no pixel centre of the image */
        ids[kept] = ip_cell_id(s->level, linear);
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) {
                pos[9 * kept + 3 * k + a] = points[row[3 * t + k]][a];
                nor[9 * kept + 3 * k + a] = ip_normal_pack(normals[row[3 * t + k]][a]);
            }
        kept++;
    }
    *culled += (uint64_t)(n - kept);
    if (ip_mesh_append(out->mesh, pos, nor, ids, (uint64_t)kept) != IP_OK) {
        *st = IP_ERR_NOMEM;
        return -1;
    }
    return kept;
}

/* 1 - cos of the angle between the unit ray `dir` and v (of length `length`), the direction
 * from the eye to a point: it grows with the angle over [0, pi], so it orders angles as they
 * do, without atan2. */
static double versine(const double dir[3], const double v[3], double length)
{
    return length > 0 ? 1.0 - ip__vec3_dot(dir, v) / length : 0.0;
}

/* The versine below which an angle is smaller than (the angle of versine `max`) less the
 * fold-back tolerance: 1 - cos(m - f) = 1 - cos m cos f - sin m sin f. Negative (no angle
 * qualifies) when m <= f. (Comparisons, not fmax(), here and in the propagation loop: fmax()
 * is a call on the x86-64 baseline, and gives the same for these values, NaN included.) */
static double foldback_limit(const ip_propagator *p, double max)
{
    double cos_m = 1.0 - max, s2 = max * (2.0 - max), sin_m = sqrt(s2 > 0.0 ? s2 : 0.0);
    if (cos_m >= p->cos_foldback) /* m <= f */
        return -1.0;
    return 1.0 - cos_m * p->cos_foldback - sin_m * p->sin_foldback;
}

/* The cell's centre (ip__sampler_cell_centre()) and the length of its diagonal. */
static void cell_centre(const ip_sampler *s, const uint32_t cell[3], double centre[3],
                        double *diagonal)
{
    ip__sampler_cell_centre(s, cell, centre);
    double d2 = 0;
    for (int a = 0; a < 3; a++) {
        double side = s->world[a][cell[a] + 1] - s->world[a][cell[a]];
        d2 += side * side;
    }
    *diagonal = sqrt(d2);
}

/* Whether any part of the cell may project into the propagator's window of the image (a
 * conservative test on its centre, widened by the cell's projected size and a 2-pixel margin).
 * `v` is the centre less the eye, `depth` its view depth. Sets the centre's image position
 * (pixels) and *pixels to the cell's projected size (its diagonal, in pixels) when it does. */
static int in_frustum(const ip_propagator *p, const double v[3], double depth, double diagonal,
                      double *x, double *y, double *pixels)
{
    if (!(depth > 0.0))
        return 0;
    ip__image_position(&p->axes, v, depth, x, y);
    *pixels = diagonal / depth * p->pixel_scale;
    double margin = 2.0 + *pixels;
    return *x >= p->window[0] - margin && *x <= p->window[2] + margin &&
           *y >= p->window[1] - margin && *y <= p->window[3] + margin;
}

/* Whether surface extracted so far hides the cell at every pixel centre it may cover. A cell
 * smaller than MIN_TEST_PIXELS on screen is tested through the aligned block of 2^k cells
 * around it that is not (up to 2^MAX_TEST_SHIFT cells a side): a box under a pixel holds no
 * pixel centre and could never be found hidden, and whatever hides the block hides every cell
 * in it (its pixel centres are among the block's, its nearest point no nearer). The cell's
 * centre seen from the eye (in_frustum()) is the box's when it is tested alone. */
static int hidden(const ip_propagator *p, const uint32_t cell[3], double pixels, double depth,
                  double x, double y)
{
    unsigned k = 0;
    while (k < MAX_TEST_SHIFT && pixels * (double)(1u << k) < MIN_TEST_PIXELS)
        k++;
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        uint32_t first = cell[a] >> k << k, end = first + (1u << k),
                 cells = p->sampler->dims[a] - 1;
        end = end < cells ? end : cells;
        lo[a] = p->sampler->world[a][first];
        hi[a] = p->sampler->world[a][end];
    }
    return k == 0 ? ip__coverage_hides_seen(p->out.coverage, lo, hi, depth, x, y)
                  : ip__coverage_hides(p->out.coverage, lo, hi);
}

/* 1 unless the clipping planes drop `cell`; only called when there are planes. */
static int cell_kept(const ip_propagator *p, const uint32_t cell[3])
{
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = p->sampler->world[a][cell[a]];
        hi[a] = p->sampler->world[a][cell[a] + 1];
    }
    return ip__clip_keeps_box(&p->clip, lo, hi);
}

/* The view depth of world point `p`. */
static double view_depth(const ip_propagator *p, const double point[3])
{
    double v[3];
    ip__vec3_sub(point, p->camera->eye, v);
    return ip__vec3_dot(v, p->basis.forward);
}

/* Offers IP_SHARE_CELLS of the farthest queued cells to a waiting worker (ip_share); puts them
 * back when it has no room. */
static ip_status share(ip_propagator *p, const double dir[3])
{
    ip_queued_cell part[IP_SHARE_CELLS];
    unsigned n = ip__depth_queue_take_far(&p->queue, part, IP_SHARE_CELLS);
    if (p->share.give(p->share.user, p->sampler->level, part, n, dir))
        return IP_OK;
    ip_status st = IP_OK;
    double centre[3], diagonal;
    for (unsigned i = 0; i < n && st == IP_OK; i++) {
        cell_centre(p->sampler, part[i].cell, centre, &diagonal);
        st = ip__depth_queue_push(&p->queue, &part[i], view_depth(p, centre));
    }
    return st;
}

ip_status ip__propagate(ip_propagator *p, const uint32_t seed[3], const double dir[3],
                        ip_engine_counts *counts)
{
    double centre[3], diagonal, v[3];
    cell_centre(p->sampler, seed, centre, &diagonal);
    ip__vec3_sub(centre, p->camera->eye, v);
    ip_queued_cell q = {{seed[0], seed[1], seed[2]}, (float)versine(dir, v, ip__vec3_length(v))};
    return ip__propagate_queued(p, &q, 1, dir, counts);
}

ip_status ip__propagate_queued(ip_propagator *p, const ip_queued_cell *cells, unsigned count,
                               const double dir[3], ip_engine_counts *counts)
{
    const uint32_t *dims = p->sampler->dims;
    ip_visited *visited = p->visited;
    const uint32_t level = p->sampler->level, shift = visited->edge_shift;
    const double *eye = p->camera->eye;
    double start = ip_now_seconds(), extracting = 0;
    uint64_t extracted = 0;
    double centre[3], diagonal;
    const int clipping = p->clip.count > 0; /* without planes no cell is tested */
    ip_status st = IP_OK;
    if (count == 0)
        return st;
    /* nearest first (depth_queue.h), in buckets of half the first cell's diagonal */
    cell_centre(p->sampler, cells[0].cell, centre, &diagonal);
    ip__depth_queue_start(&p->queue, view_depth(p, centre), 0.5 * diagonal);
    for (unsigned i = 0; i < count && st == IP_OK; i++) {
        cell_centre(p->sampler, cells[i].cell, centre, &diagonal);
        st = ip__depth_queue_push(&p->queue, &cells[i], view_depth(p, centre));
    }
    ip_queued_cell q;
    while (st == IP_OK && ip__depth_queue_pop(&p->queue, &q)) {
        unsigned mc;
        /* The clock is read around one extraction in TIMING_STRIDE (a clock read costs about
         * what a third of a cell's marching cubes does); the split is an estimate. */
        int timed = extracted++ % TIMING_STRIDE == 0;
        double t0 = timed ? ip_now_seconds() : 0;
        int n = ip__extract_cell(p->sampler, &p->out, q.cell, p->iso, &mc, &counts->culled, &st);
        if (timed)
            extracting += TIMING_STRIDE * (ip_now_seconds() - t0);
        if (n < 0)
            break;
        counts->cells++;
        counts->triangles += (uint64_t)n;
        unsigned faces = ip__mc_crossed_faces(mc);
        double folded = faces ? foldback_limit(p, q.max_versine) : 0.0;
        /* The bitmap of the cell's brick, which holds most of its neighbours (it exists: the
         * cell was marked before it was queued). */
        atomic_uint_fast64_t *home = faces ? ip__visited_cell_bitmap(visited, level, q.cell) : NULL;
        for (int f = 0; f < 6 && st == IP_OK; f++) {
            if (!(faces & (1u << f)))
                continue;
            /* face f: -x, +x, -y, +y, -z, +z */
            unsigned axis = (unsigned)f >> 1;
            if (f & 1 ? q.cell[axis] + 2 >= dims[axis] : q.cell[axis] == 0)
                continue; /* beyond the volume */
            uint32_t n3[3] = {q.cell[0], q.cell[1], q.cell[2]};
            n3[axis] += f & 1 ? 1u : UINT32_MAX;
            int same = home && n3[axis] >> shift == q.cell[axis] >> shift;
            if ((same ? ip__visited_test_in(visited, home, n3)
                      : ip__visited_test(visited, level, n3)) ||
                (clipping && !cell_kept(p, n3)))
                continue;
            cell_centre(p->sampler, n3, centre, &diagonal);
            double v[3]; /* the distance as the rays' band test takes it (lod.h) */
            double distance = ip__lod_centre_distance(centre, eye, v),
                   a = versine(dir, v, distance);
            if (a > p->cutoff_versine || a < folded)
                continue;
            double depth = ip__vec3_dot(v, p->basis.forward), x, y, pixels;
            if (!in_frustum(p, v, depth, diagonal, &x, &y, &pixels))
                continue;
            if (!ip__lod_in_band(distance, p->near_distance, p->far_distance))
                continue; /* another level's band (lod.h): the resolution boundary */
            if (p->out.coverage && hidden(p, n3, pixels, depth, x, y)) {
                counts->deferred++; /* left unmarked: a ray that seeds it extracts it */
                continue;
            }
            int was = same ? ip__visited_mark_in(visited, home, n3)
                           : ip__visited_mark(visited, level, n3);
            if (was < 0)
                st = IP_ERR_NOMEM;
            else if (!was)
                st = ip__depth_queue_push(
                    &p->queue,
                    &(ip_queued_cell){{n3[0], n3[1], n3[2]},
                                      (float)(a > q.max_versine ? a : q.max_versine)},
                    depth);
        }
        /* the farthest part of a long queue to a worker waiting for cells */
        if (p->share.hungry && extracted % SHARE_STRIDE == 0 &&
            p->queue.count >= 2 * IP_SHARE_CELLS &&
            atomic_load_explicit(p->share.hungry, memory_order_relaxed) > 0 && st == IP_OK)
            st = share(p, dir);
    }
    double total = ip_now_seconds() - start;
    extracting = extracting < total ? extracting : total;
    counts->extraction_seconds += extracting;
    counts->propagation_seconds += total - extracting;
    return st;
}
