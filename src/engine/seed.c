/* SPDX-License-Identifier: BSD-3-Clause */
/* Ray seeding through the min/max octree: root -> bricks -> sub-blocks -> cells, front to back
 * (the bricks of a short stretch of ray by a DDA over them instead of down the octree). */
#include <math.h>
#include <string.h>

#include "format.h"
#include "internal.h"
#include "lod.h"
#include "seed.h"
#include "vec3.h"

/* The ray in the level's index space, where cell (i, j, k) is the box [i, i+1] x ... . The
 * parameter t stays the world distance along the ray. */
typedef struct index_ray {
    double origin[3], dir[3];
    double inv_dir[3]; /* 1 / dir (0 where dir is 0, unused there): clip() runs per node */
    double len;        /* the largest |dir| component, for dda_init()'s nudge */
    const double *world_origin, *world_dir;
    double u[3], w[3]; /* a unit basis across world_dir, for classify_cell() */
} index_ray;

/* A unit basis (u, w) across the unit direction d. */
static void across_basis(const double d[3], double u[3], double w[3])
{
    int k = fabs(d[0]) < fabs(d[1]) ? (fabs(d[0]) < fabs(d[2]) ? 0 : 2)
                                    : (fabs(d[1]) < fabs(d[2]) ? 1 : 2);
    double axis[3] = {0, 0, 0};
    axis[k] = 1;
    ip__vec3_cross(d, axis, u);
    double un = ip__vec3_length(u); /* > 0: the axis is the one least along d */
    for (int i = 0; i < 3; i++)
        u[i] /= un;
    ip__vec3_cross(d, u, w);
}

/* Clips the ray to the index box [lo, hi]; returns 0 when it misses it or only behind t0.
 * *in and *out (either may be NULL): the axis of the face the ray enters and leaves the box
 * through, -1 where the stretch starts (ends) inside it, at the t0 (t1) it was given. */
static int clip_axes(const index_ray *r, const double lo[3], const double hi[3], double *t0,
                     double *t1, int *in, int *out)
{
    double a = *t0, b = *t1;
    int enter = -1, leave = -1;
    for (int k = 0; k < 3; k++) {
        if (r->dir[k] == 0.0) {
            if (r->origin[k] < lo[k] || r->origin[k] > hi[k])
                return 0;
            continue;
        }
        double inv = r->inv_dir[k];
        double ta = (lo[k] - r->origin[k]) * inv, tb = (hi[k] - r->origin[k]) * inv;
        if (ta > tb) {
            double t = ta;
            ta = tb;
            tb = t;
        }
        if (ta > a) {
            a = ta;
            enter = k;
        }
        if (tb < b) {
            b = tb;
            leave = k;
        }
    }
    *t0 = a;
    *t1 = b;
    if (in)
        *in = enter;
    if (out)
        *out = leave;
    return a <= b;
}

static int clip(const index_ray *r, const double lo[3], const double hi[3], double *t0, double *t1)
{
    return clip_axes(r, lo, hi, t0, t1, NULL, NULL);
}

/* A 3D DDA over a grid of `n` cells of edge `edge` (index units) starting at `base`. */
typedef struct dda {
    int32_t i[3], n[3], step[3];
    double t_max[3], t_delta[3], t, t_end;
    int in_axis;    /* the axis of the face the ray entered the current cell through; -1 for the
                    first cell (the ray enters the grid there, or starts inside it) */
    double base[3]; /* the grid's first corner */
    double edge;    /* its cells' edge */
    int parallel;   /* the ray runs parallel to some axis's faces */
    int peek;       /* the axis dda_exit() found the ray leaves along, or -1 */
} dda;

static void dda_init(dda *d, const index_ray *r, const double base[3], double edge,
                     const uint32_t n[3], double t0, double t1)
{
    double mid = t0; /* the entry point: nudge inwards along the ray */
    mid += 1e-9 * edge / (r->len > 0 ? r->len : 1);
    if (mid > t1)
        mid = 0.5 * (t0 + t1);
    for (int k = 0; k < 3; k++) {
        double p = r->origin[k] + mid * r->dir[k];
        int32_t c = (int32_t)floor((p - base[k]) / edge);
        c = c < 0 ? 0 : c >= (int32_t)n[k] ? (int32_t)n[k] - 1 : c;
        d->i[k] = c;
        d->n[k] = (int32_t)n[k];
        if (r->dir[k] > 0) {
            d->step[k] = 1;
            d->t_max[k] = (base[k] + (c + 1) * edge - r->origin[k]) / r->dir[k];
            d->t_delta[k] = edge / r->dir[k];
        } else if (r->dir[k] < 0) {
            d->step[k] = -1;
            d->t_max[k] = (base[k] + c * edge - r->origin[k]) / r->dir[k];
            d->t_delta[k] = -edge / r->dir[k];
        } else {
            d->step[k] = 0;
            d->t_max[k] = INFINITY;
            d->t_delta[k] = INFINITY;
        }
    }
    d->t = t0;
    d->t_end = t1;
    d->in_axis = -1;
    d->parallel = 0;
    d->peek = -1;
    for (int k = 0; k < 3; k++) {
        d->base[k] = base[k];
        d->parallel |= d->step[k] == 0;
    }
    d->edge = edge;
}

/* The axis of the face the ray leaves the current cell through, and there *exit_t; -1 when
 * the stretch ends in the cell or on the grid's boundary (then *exit_t is its end). */
static IP_ALWAYS_INLINE int dda_exit(dda *d, double *exit_t)
{
    int k = d->t_max[0] < d->t_max[1] ? (d->t_max[0] < d->t_max[2] ? 0 : 2)
                                      : (d->t_max[1] < d->t_max[2] ? 1 : 2);
    d->peek = k; /* dda_next() steps along it */
    *exit_t = d->t_max[k] < d->t_end ? d->t_max[k] : d->t_end;
    int steps = !(d->t_max[k] > d->t_end) && d->step[k] != 0;
    return steps && d->i[k] + d->step[k] >= 0 && d->i[k] + d->step[k] < d->n[k] ? k : -1;
}

/* The current cell's exit parameter; advances to the next cell. Returns 0 when past the end. */
static IP_ALWAYS_INLINE int dda_next(dda *d, double *exit_t)
{
    int k = d->peek >= 0                ? d->peek
            : d->t_max[0] < d->t_max[1] ? (d->t_max[0] < d->t_max[2] ? 0 : 2)
                                        : (d->t_max[1] < d->t_max[2] ? 1 : 2);
    d->peek = -1;
    *exit_t = d->t_max[k] < d->t_end ? d->t_max[k] : d->t_end;
    if (d->t_max[k] > d->t_end || d->step[k] == 0)
        return 0;
    d->t = d->t_max[k];
    d->i[k] += d->step[k];
    d->t_max[k] += d->t_delta[k];
    d->in_axis = k;
    return d->i[k] >= 0 && d->i[k] < d->n[k];
}

static int active(const float *range, float iso)
{
    return ip__range_active(range[0], range[1], iso);
}

/* Classifies the ray against the cell's triangles as a rasteriser would classify its pixel
 * centre: each triangle is projected centrally around the ray (point-in-triangle is the same
 * for every central projection through the ray) and the ray's distance to its edges is
 * measured as an angle. 3: inside a triangle by at least the margin; 2: inside one, within
 * the margin of its edge; 1: outside every triangle, within the margin of one; 0: none.
 * `cell` (level coordinates), its case `mc` and corner values; the triangles are built in the
 * cell's own frame (corner 0 at the origin), where the ray's origin is taken too. */
static IP_ALWAYS_INLINE int classify_cell(const ip_seeder *s, const index_ray *r,
                                          const uint32_t cell[3], unsigned mc,
                                          const float values[8])
{
    static const float zero[3] = {0, 0, 0};
    float points[12][3], origin[3], far[3], size[3];
    double ro[3];
    ip__sampler_cell_box(s->sampler, cell, origin, far);
    for (int k = 0; k < 3; k++) { /* the cell's frame keeps precision in large volumes */
        ro[k] = r->world_origin[k] - (double)origin[k];
        size[k] = far[k] - origin[k];
    }
    unsigned crossed = ip__mc_cell_edge_points(values, mc, s->iso, zero, size, points);
    /* each crossing point projected once, though up to 4 triangles share it */
    double p[12][2];
    unsigned behind = 0;
    const double *rd = r->world_dir, *u = r->u, *w = r->w;
    for (unsigned e = 0; e < 12; e++) {
        if (!(crossed >> e & 1u))
            continue;
        double d[3] = {points[e][0] - ro[0], points[e][1] - ro[1], points[e][2] - ro[2]};
        double depth = ip__vec3_dot(d, rd);
        behind |= (unsigned)!(depth > 0) << e;
        p[e][0] = ip__vec3_dot(d, u) / depth;
        p[e][1] = ip__vec3_dot(d, w) / depth;
    }
    const int8_t *row = s->sampler->mc_rows[mc];
    int n = ip__mc_triangle_count[mc], best = 0;
    for (int t = 0; t < n && best < 3; t++) {
        const int8_t *tri = row + 3 * t;
        if (behind >> tri[0] & 1u || behind >> tri[1] & 1u || behind >> tri[2] & 1u)
            continue;
        const double *p0 = p[tri[0]], *p1 = p[tri[1]], *p2 = p[tri[2]];
        double area = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
        double least = INFINITY;
        for (int j = 0; j < 3; j++) {
            const double *a = p[tri[j]], *b = p[tri[(j + 1) % 3]];
            double ex = b[0] - a[0], ey = b[1] - a[1], len = sqrt(ex * ex + ey * ey);
            /* signed distance of the ray (the origin) to the edge, positive inside */
            double dist = len > 0 ? (ex * (0 - a[1]) - ey * (0 - a[0])) / len : 0;
            least = fmin(least, area >= 0 ? dist : -dist);
        }
        int kind = area != 0 && least >= s->margin ? 3
                   : area != 0 && least >= 0       ? 2
                   : least >= -s->margin           ? 1
                                                   : 0;
        best = kind > best ? kind : best;
    }
    return best;
}

/* floor(x) for |x| < 2^62 (floor() is a call on the x86-64 baseline). */
static inline int64_t floor_index(double x)
{
    int64_t i = (int64_t)x; /* toward zero */
    return i - ((double)i > x);
}

/* 1 when the ray moves into another cell of the level between t = u0 and u1 across a plane
 * along an axis other than k. */
static int changes_cell(const index_ray *r, int k, double u0, double u1)
{
    for (int j = 0; j < 3; j++)
        if (j != k && floor_index(r->origin[j] + u0 * r->dir[j]) !=
                          floor_index(r->origin[j] + u1 * r->dir[j]))
            return 1;
    return 0;
}

/* The faces of the box [lo, hi] (index units: one of the level's cells, or with `coarse` a
 * larger box of whole cells) inside the region of cells
 * [in_lo, in_hi) that the ray passes within s->reach of over [ta, tb] where it may leave cells
 * beyond them unentered: bit 2k is the low face along axis k, bit 2k + 1 the high one. The ray
 * enters the box through a face along axis `in` and leaves it through one along `out` (-1:
 * neither; it starts or ends inside, or on the boundary of the caller's region). Beyond a face
 * it crosses, a cell's only neighbour it comes near is the cell it enters; a larger box's face
 * counts when the ray moves into another of the level's cells within reach of the crossing. */
static unsigned near_faces(const ip_seeder *s, const index_ray *r, int coarse, const double lo[3],
                           const double hi[3], const uint32_t in_lo[3], const uint32_t in_hi[3],
                           double ta, double tb, int in, int out)
{
    unsigned m = 0;
    for (int k = 0; k < 3; k++) { /* faces on the region's boundary lead out of it: not here */
        double a = r->origin[k] + ta * r->dir[k], b = r->origin[k] + tb * r->dir[k];
        double least = a < b ? a : b, most = a < b ? b : a;
        m |= (unsigned)(least - lo[k] < s->reach[k] && lo[k] > (double)in_lo[k]) << 2 * k;
        m |= (unsigned)(hi[k] - most < s->reach[k] && hi[k] < (double)in_hi[k]) << (2 * k + 1);
    }
    if (!m)
        return 0;
    /* within reach of a plane it crosses at t from t - within to t + within (as
     * dda_near_faces()) */
    if (in >= 0 && (!coarse || !changes_cell(r, in, ta - s->within[in], ta + s->within[in])))
        m &= ~(1u << (2 * in + (r->dir[in] < 0)));
    if (out >= 0 && (!coarse || !changes_cell(r, out, tb - s->within[out], tb + s->within[out])))
        m &= ~(1u << (2 * out + (r->dir[out] > 0)));
    return m;
}

/* The first plane the ray crosses after the current cell's exit along axis `out`: the least
 * t_max of the other axes. */
static IP_ALWAYS_INLINE double next_other(const dda *d, int out)
{
    double a = d->t_max[out == 0 ? 1 : 0], b = d->t_max[out == 2 ? 1 : 2];
    return a < b ? a : b;
}

/* near_faces() of the DDA's current cell, within the DDA's grid (the caller's region), from
 * the DDA's own crossings: the ray was last at the plane behind the cell along axis k at
 * t_max[k] - t_delta[k] and reaches the plane ahead at t_max[k]. `in` and `out` as
 * near_faces(). For a grid of the level's cells (`coarse` 0) the faces it crosses there are
 * left out; for a coarser one they count when the ray moves into another of the level's cells
 * within reach of them: `in_changes` and *out_changes say so for the planes it crosses at t_in
 * and t_out (the latter set here: it is the next cell's in_changes). */
static IP_ALWAYS_INLINE unsigned dda_near_faces(const ip_seeder *s, const index_ray *r,
                                                const dda *d, int coarse, double before,
                                                double t_in, double t_out, int in, int out,
                                                int in_changes, int *out_changes)
{
    /* Along an axis the ray runs parallel to, t_max and t_delta are infinite: both tests
     * fail there (NaN and infinity), and the position says instead. The ray comes within
     * reach of a face it does not cross only where it crosses two planes within reach of
     * each other: past the cell's first and last, most cells are told apart by the crossings
     * just before and after theirs (`before`: where it entered the previous cell). */
    unsigned m = 0;
    int quiet = !d->parallel && in >= 0 && out >= 0 && t_in - before >= s->within_most &&
                next_other(d, out) - t_out >= s->within_most;
    for (int k = 0; k < 3 && !quiet; k++) {
        unsigned behind = d->step[k] < 0; /* the face behind the ray: 0 low, 1 high */
        int32_t first = behind ? d->n[k] - 1 : 0, last = behind ? 0 : d->n[k] - 1;
        unsigned near_behind = (unsigned)(t_in - (d->t_max[k] - d->t_delta[k]) < s->within[k]) &
                               (unsigned)(d->i[k] != first); /* not the grid's own face */
        unsigned near_ahead =
            (unsigned)(d->t_max[k] - t_out < s->within[k]) & (unsigned)(d->i[k] != last);
        m |= (near_behind << behind | near_ahead << (1u - behind)) << 2 * k;
    }
    if (in >= 0) /* crossed there: the cell's neighbour is where the ray comes from */
        m &= ~(1u << (2 * in + (d->step[in] < 0)));
    if (out >= 0)
        m &= ~(1u << (2 * out + (d->step[out] > 0)));
    if (d->parallel) /* (never quiet) */
        for (int k = 0; k < 3; k++) {
            if (d->step[k] != 0)
                continue;
            double p = r->origin[k] - d->base[k] - d->edge * (double)d->i[k];
            m |= ((unsigned)(p < s->reach[k] && d->i[k] != 0) |
                  (unsigned)(d->edge - p < s->reach[k] && d->i[k] != d->n[k] - 1) << 1)
                 << 2 * k;
        }
    if (coarse && in >= 0 && in_changes)
        m |= 1u << (2 * in + (d->step[in] < 0));
    if (coarse && out >= 0) {
        *out_changes = changes_cell(r, out, t_out - s->within[out], t_out + s->within[out]);
        m |= (unsigned)*out_changes << (2 * out + (d->step[out] > 0));
    }
    return m;
}

/* 1 when `cell` lies in the seeder's distance band (lod.h), as propagation decides it. */
static int in_band(const ip_seeder *s, const index_ray *r, const uint32_t cell[3])
{
    return ip__lod_cell_in_band(s->sampler, cell, r->world_origin, s->band_near, s->band_far);
}

/* 1 when cell c is already among the ray's cells. */
static int found_already(const ip_seeder *s, const int64_t c[3])
{
    for (unsigned i = 0; i < s->found_count; i++)
        if (s->found[i][0] == c[0] && s->found[i][1] == c[1] && s->found[i][2] == c[2])
            return 1;
    return 0;
}

/* Tests cell c, which the ray passes within s->reach of without entering it: when it is
 * active and the ray passes within the margin of one of its triangles (or inside one, by
 * rounding), it is added as a near miss (extracted alone, never the seed). Returns -1 when
 * its brick could not be read, else 0. */
static int near_cell(ip_seeder *s, const index_ray *r, const int64_t c[3])
{
    const ip_layout *l = s->layout;
    const ip_level_layout *lv = &l->levels[s->level];
    uint32_t cell[3], brick[3], origin[3], extent[3], n[3], at[3];
    for (int k = 0; k < 3; k++) {
        if (c[k] < 0 || c[k] + 1 >= (int64_t)lv->dims[k])
            return 0; /* beyond the volume */
        cell[k] = (uint32_t)c[k];
        brick[k] = cell[k] / l->brick_edge;
    }
    const float *ranges = ip__seeder_brick(s, brick, origin, extent, n); /* its sub-block's: */
    uint32_t per = l->brick_edge / l->subblock_edge;
    for (int k = 0; k < 3; k++)
        at[k] = (cell[k] - origin[k]) / l->subblock_edge;
    if (!active(&ranges[2 * (at[0] + per * (at[1] + per * at[2]))], s->iso) ||
        s->found_count + 1 >= IP_SEED_MAX_CELLS || found_already(s, c))
        return 0;
    uint32_t c1[3] = {cell[0] + 1, cell[1] + 1, cell[2] + 1};
    if ((s->clip.count && !ip__clip_keeps_samples(&s->clip, l, s->level, cell, c1)) ||
        (s->banded && !in_band(s, r, cell)))
        return 0;
    float values[8];
    unsigned mc;
    if (ip__sampler_cell_case(s->sampler, cell, s->iso, values, &mc) < 0)
        return -1;
    if (mc == 0 || mc == 255)
        return 0;
    s->near_tested++;
    if (classify_cell(s, r, cell, mc, values))
        memcpy(s->found[s->found_count++], cell, sizeof cell);
    return 0;
}

/* The cells the ray passes within s->reach of, over [ta, tb], while it runs through the box
 * walk_lo .. walk_hi (index units, whole cells): those outside the box own_lo .. own_hi (whose
 * cells are the caller's to walk, or inactive; empty when lo > hi) and inside the cells
 * [in_lo, in_hi) (the region the caller walks) are tested by near_cell(). The ray enters the
 * walked box through a face along axis `in` and leaves it along `out` (near_faces()).
 * Returns -1 when a brick could not be read, else 0. */
static int near_cells(ip_seeder *s, const index_ray *r, const double walk_lo[3],
                      const double walk_hi[3], const double own_lo[3], const double own_hi[3],
                      const uint32_t in_lo[3], const uint32_t in_hi[3], double ta, double tb,
                      int in, int out)
{
    uint32_t n[3];
    for (int k = 0; k < 3; k++)
        n[k] = (uint32_t)(walk_hi[k] - walk_lo[k]);
    dda d;
    dda_init(&d, r, walk_lo, 1.0, n, ta, tb);
    d.in_axis = in;
    for (;;) {
        double exit_t;
        int leave = dda_exit(&d, &exit_t);
        int64_t c[3];
        double lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            c[k] = (int64_t)walk_lo[k] + d.i[k];
            lo[k] = (double)c[k];
            hi[k] = lo[k] + 1.0;
        }
        unsigned m = near_faces(s, r, 0, lo, hi, in_lo, in_hi, d.t, exit_t, d.in_axis,
                                leave < 0 ? out : leave);
        /* the neighbours across those faces, diagonal ones included: along each axis the
         * cell's own row, and the row below or above where the ray passes near that face
         * (near_faces() leaves out the faces on the region's boundary) */
        if (m) {
            int steps[3][3], count[3];
            for (int k = 0; k < 3; k++) {
                count[k] = 0;
                steps[k][count[k]++] = 0;
                if (m >> 2 * k & 1u)
                    steps[k][count[k]++] = -1;
                if (m >> (2 * k + 1) & 1u)
                    steps[k][count[k]++] = 1;
            }
            for (int z = 0; z < count[2]; z++)
                for (int y = 0; y < count[1]; y++)
                    for (int x = 0; x < count[0]; x++) {
                        int64_t nb[3] = {c[0] + steps[0][x], c[1] + steps[1][y],
                                         c[2] + steps[2][z]};
                        int outside = 0;
                        for (int k = 0; k < 3; k++)
                            outside |= (double)nb[k] < own_lo[k] || (double)nb[k] >= own_hi[k];
                        if ((x | y | z) && outside && near_cell(s, r, nb) < 0)
                            return -1;
                    }
        }
        if (!dda_next(&d, &exit_t))
            return 0;
    }
}

/* After the walk of the box lo .. hi (whole cells), which the ray crossed over [ta, tb],
 * entering it along `in` and leaving along `out`: near_cells() of the box when the ray passes
 * near a face of it that it does not cross. Where the walk stopped (`found`), only up to the
 * cell it stopped in (s->hit_t): beyond, the ray needs nothing. */
static int near_box(ip_seeder *s, const index_ray *r, const double lo[3], const double hi[3],
                    const uint32_t in_lo[3], const uint32_t in_hi[3], double ta, double tb, int in,
                    int out, int found)
{
    if (found) {
        tb = s->hit_t;
        out = -1;
    }
    if (!near_faces(s, r, 1, lo, hi, in_lo, in_hi, ta, tb, in, out))
        return 0;
    return near_cells(s, r, lo, hi, lo, hi, in_lo, in_hi, ta, tb, in, out);
}

/* Tests the cells of one sub-block (cells [lo, hi) in level coordinates) along the ray; `side`
 * is where the sub-block lies against the clipping planes (ip__clip_keeps_box()), its cells
 * tested against them only when it straddles one. */
static int walk_cells(ip_seeder *s, const index_ray *r, const uint32_t lo[3], const uint32_t hi[3],
                      int side, double t0, double t1)
{
    double base[3] = {lo[0], lo[1], lo[2]};
    uint32_t n[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    /* A sub-block lies in one brick: look it up once, not per cell. Nothing below reads
     * through the sampler, so the brick stays pinned in its slot. */
    const ip_brick *brick = ip__sampler_cell_brick(s->sampler, lo);
    if (!brick)
        return -1;
    ptrdiff_t corners[8];
    ip__corner_offsets(brick, corners);
    /* The cells come in runs through one cell group (cache.h): its range is read when the run
     * enters it, and the corners of none of its cells when no cell of it can be active. The
     * cells visited and their order stay those of the cell DDA. */
    size_t groups_x = ip_cell_groups(brick->extent[0]),
           groups_xy = groups_x * ip_cell_groups(brick->extent[1]);
    size_t group = SIZE_MAX;
    int group_active = 1;
    dda d;
    dda_init(&d, r, base, 1.0, n, t0, t1);
    double before = -INFINITY; /* where the ray entered the previous cell */
    for (;;) {
        s->nodes++;
        uint32_t c[3] = {lo[0] + (uint32_t)d.i[0], lo[1] + (uint32_t)d.i[1],
                         lo[2] + (uint32_t)d.i[2]};
        size_t at = (c[0] - brick->origin[0]) / IP_CELL_GROUP +
                    groups_x * ((c[1] - brick->origin[1]) / IP_CELL_GROUP) +
                    groups_xy * ((c[2] - brick->origin[2]) / IP_CELL_GROUP);
        if (at != group && s->use_group_ranges) {
            static const ptrdiff_t pair[2] = {0, 1};
            float range[2];
            ip__samples_gather(brick->group_ranges, s->layout->type, 2 * at, pair, 2, range);
            group = at;
            group_active = ip__range_active(range[0], range[1], s->iso);
        }
        float values[8];
        unsigned mc = 0;
        int kind = 0;
        uint32_t c1[3] = {c[0] + 1, c[1] + 1, c[2] + 1};
        if (group_active &&
            (side == IP__CLIP_KEEPS_ALL ||
             ip__clip_keeps_samples(&s->clip, s->layout, s->level, c, c1)) &&
            (!s->banded || in_band(s, r, c))) {
            ip__cell_values(brick, s->layout->type, corners, c, values);
            mc = ip__mc_case(values, s->iso);
            s->cells_read++;
        }
        if (mc != 0 && mc != 255) {
            s->cells_tested++;
            kind = classify_cell(s, r, c, mc, values);
            if (kind >= 2 && s->seed_index < 0)
                s->seed_index = (int)s->found_count; /* the first cell the ray is inside */
            if (kind && s->found_count < IP_SEED_MAX_CELLS)
                memcpy(s->found[s->found_count++], c, sizeof c);
        }
        /* the sub-block's cells beside this one that the ray passes close by (their brick
         * is this one: the sampler finds it in its slot, and `brick` stays pinned) */
        double exit_t;
        int leave = dda_exit(&d, &exit_t);
        unsigned near = dda_near_faces(s, r, &d, 0, before, d.t, exit_t, d.in_axis, leave, 0, NULL);
        before = d.t;
        if (near) {
            double clo[3] = {c[0], c[1], c[2]}, chi[3] = {c1[0], c1[1], c1[2]};
            if (near_cells(s, r, clo, chi, clo, chi, lo, hi, d.t, exit_t, d.in_axis, leave) < 0)
                return -1;
        }
        if (kind == 3) {
            s->hit_t = exit_t;
            return 1;
        }
        if (!dda_next(&d, &exit_t))
            return 0;
    }
}

/* Walks the sub-blocks of brick `b` front to back. */
static int walk_brick(ip_seeder *s, const index_ray *r, const uint32_t b[3], double t0, double t1)
{
    const ip_layout *l = s->layout;
    uint32_t origin[3], extent[3], n[3];
    const float *ranges = ip__seeder_brick(s, b, origin, extent, n);
    uint32_t per = l->brick_edge / l->subblock_edge, se = l->subblock_edge;
    double base[3] = {origin[0], origin[1], origin[2]};
    /* the brick's cells, the region its sub-blocks' near passes look into */
    uint32_t cells_lo[3] = {origin[0], origin[1], origin[2]},
             cells_hi[3] = {origin[0] + extent[0] - 1, origin[1] + extent[1] - 1,
                            origin[2] + extent[2] - 1};
    dda d;
    dda_init(&d, r, base, se, n, t0, t1);
    int changes = 0; /* the ray moves into another cell within reach of the last plane crossed */
    double before = -INFINITY; /* where the ray entered the previous sub-block */
    for (;;) {
        s->nodes++;
        int32_t at[3] = {d.i[0], d.i[1], d.i[2]};
        double enter_t = d.t, exit_t;
        int in = d.in_axis, out = dda_exit(&d, &exit_t);
        /* the faces the ray passes close to, to the end of the sub-block (where it stops, if
         * it does, is known after the walk) */
        unsigned near =
            dda_near_faces(s, r, &d, 1, before, enter_t, exit_t, in, out, changes, &changes);
        before = enter_t;
        int more = dda_next(&d, &exit_t);
        uint32_t sb = (uint32_t)at[0] + per * ((uint32_t)at[1] + per * (uint32_t)at[2]);
        uint32_t lo[3], hi[3], sub[3] = {(uint32_t)at[0], (uint32_t)at[1], (uint32_t)at[2]};
        int found = 0, is_active = active(&ranges[2 * sb], s->iso);
        if (is_active || near)
            ip__seeder_subblock_cells(s, origin, extent, sub, lo, hi);
        if (is_active) {
            int side = ip__clip_keeps_samples(&s->clip, l, s->level, lo, hi);
            found = side ? walk_cells(s, r, lo, hi, side, enter_t, exit_t) : 0;
        }
        if (found < 0)
            return found;
        if (near || found) { /* where it stopped, to there only: near_box() looks again */
            double blo[3] = {lo[0], lo[1], lo[2]}, bhi[3] = {hi[0], hi[1], hi[2]};
            if (near_box(s, r, blo, bhi, cells_lo, cells_hi, enter_t, exit_t, in, out, found) < 0)
                return -1;
        }
        if (found)
            return found;
        if (!more)
            return 0;
    }
}

typedef struct child_hit {
    uint32_t node[3];
    double t0, t1;
    int in, out; /* the axes of the faces the ray enters and leaves it through (near_faces()) */
    int walk;    /* active and kept: walked; else only looked beside (near passes) */
} child_hit;

static int walk_node(ip_seeder *s, const index_ray *r, uint32_t depth, const uint32_t node[3],
                     double t0, double t1)
{
    s->nodes++;
    if (depth == 0)
        return walk_brick(s, r, node, t0, t1);
    child_hit hits[8];
    int count = 0;
    /* The children's boxes (node_box()) share their planes: along each axis, the ray's
     * parameters at the low and high planes of the low (0) and high (1) children, ordered as
     * clip() orders them, computed once for the 8 children from the same operands as clip()
     * would (so the same values): a child is then clip() by lookups. */
    const ip_level_layout *lv = &s->layout->levels[s->level];
    uint64_t span = (uint64_t)s->layout->brick_edge << (depth - 1);
    double enter[3][2], leave[3][2];
    int within[3][2]; /* where the ray runs along the planes: inside the child's slab */
    for (int k = 0; k < 3; k++) {
        uint64_t cells = lv->dims[k] - 1, a = 2 * node[k] * span;
        for (int h = 0; h < 2; h++, a += span) {
            double lo = (double)a, hi = (double)(a + span < cells ? a + span : cells);
            within[k][h] = !(r->origin[k] < lo || r->origin[k] > hi);
            double ta = (lo - r->origin[k]) * r->inv_dir[k];
            double tb = (hi - r->origin[k]) * r->inv_dir[k];
            enter[k][h] = ta > tb ? tb : ta;
            leave[k][h] = ta > tb ? ta : tb;
        }
    }
    /* Every child the ray enters, active or not: beside an inactive one, the ray may pass
     * close to an active sibling's cells (near_box()). */
    const uint32_t *grid = s->grid[depth - 1];
    for (int c = 0; c < 8; c++) {
        uint32_t ch[3];
        for (int k = 0; k < 3; k++)
            ch[k] = 2 * node[k] + ((c >> k) & 1);
        if (ch[0] >= grid[0] || ch[1] >= grid[1] || ch[2] >= grid[2])
            continue;
        double a = t0, b = t1;
        int missed = 0, in = -1, out = -1;
        for (int k = 0; k < 3; k++) {
            int h = (c >> k) & 1;
            if (r->dir[k] == 0.0) {
                missed |= !within[k][h];
                continue;
            }
            if (enter[k][h] > a) {
                a = enter[k][h];
                in = k;
            }
            if (leave[k][h] < b) {
                b = leave[k][h];
                out = k;
            }
        }
        if (missed || !(a <= b))
            continue;
        int walk =
            ip__seeder_node_active(s, depth - 1, ch) && ip__seeder_node_kept(s, depth - 1, ch);
        int at = count++;
        while (at > 0 && hits[at - 1].t0 > a) { /* insertion sort: front to back */
            hits[at] = hits[at - 1];
            at--;
        }
        hits[at] = (child_hit){{ch[0], ch[1], ch[2]}, a, b, in, out, walk};
    }
    uint32_t in_lo[3], in_hi[3]; /* the node's cells: where its children's near passes look */
    ip__seeder_node_cells(s, depth, node, in_lo, in_hi);
    for (int i = 0; i < count; i++) {
        int found =
            hits[i].walk ? walk_node(s, r, depth - 1, hits[i].node, hits[i].t0, hits[i].t1) : 0;
        if (found < 0)
            return found;
        double lo[3], hi[3];
        ip__seeder_node_box(s, depth - 1, hits[i].node, lo, hi);
        if (near_box(s, r, lo, hi, in_lo, in_hi, hits[i].t0, hits[i].t1, hits[i].in, hits[i].out,
                     found) < 0)
            return -1;
        if (found)
            return found;
    }
    return 0;
}

/* The bricks along the ray between t0 and t1 front to back, by a DDA over the level's bricks
 * rather than down the octree: for a short stretch of the ray, which crosses few bricks, this
 * costs less than the descent to them. The same bricks are walked in the same order: those
 * active and kept by the clipping planes. */
static int walk_bricks(ip_seeder *s, const index_ray *r, double t0, double t1)
{
    static const double base[3] = {0, 0, 0};
    const uint32_t *grid = s->grid[0];
    dda d;
    dda_init(&d, r, base, s->layout->brick_edge, grid, t0, t1);
    const ip_level_layout *lv = &s->layout->levels[s->level];
    static const uint32_t cells_lo[3] = {0, 0, 0};
    uint32_t cells_hi[3] = {lv->dims[0] - 1, lv->dims[1] - 1, lv->dims[2] - 1};
    int changes = 0;           /* as in walk_brick() */
    double before = -INFINITY; /* where the ray entered the previous brick */
    for (;;) {
        s->nodes++;
        uint32_t b[3] = {(uint32_t)d.i[0], (uint32_t)d.i[1], (uint32_t)d.i[2]};
        double enter_t = d.t, exit_t;
        int in = d.in_axis, out = dda_exit(&d, &exit_t);
        unsigned near =
            dda_near_faces(s, r, &d, 1, before, enter_t, exit_t, in, out, changes, &changes);
        before = enter_t;
        int more = dda_next(&d, &exit_t);
        int found = ip__seeder_node_active(s, 0, b) && ip__seeder_node_kept(s, 0, b)
                        ? walk_brick(s, r, b, enter_t, exit_t)
                        : 0;
        if (found < 0)
            return found;
        if (near || found) { /* as in walk_brick() */
            double lo[3], hi[3];
            ip__seeder_node_box(s, 0, b, lo, hi);
            if (near_box(s, r, lo, hi, cells_lo, cells_hi, enter_t, exit_t, in, out, found) < 0)
                return -1;
        }
        if (found)
            return found;
        if (!more)
            return 0;
    }
}

void ip__seeder_init(ip_seeder *s, ip_sampler *sampler, float iso, double pixel_angle)
{
    memset(s, 0, sizeof *s);
    s->sampler = sampler;
    s->store = ip_cache_store(sampler->cache);
    s->layout = sampler->layout;
    s->level = sampler->level;
    s->iso = iso;
    s->use_group_ranges = 1;
    s->short_walk = IP_SEED_SHORT_WALK;
    s->margin = IP_SEED_MARGIN_PIXELS * pixel_angle;
    s->thick = IP_SEED_REACH_PIXELS * pixel_angle;
    for (int k = 0; k < 3; k++)
        s->scale[k] = s->layout->spacing[k] * (double)(1u << s->level);
    /* The node grid and the first node's range of every depth, so that a child's range is
     * one multiply-add away: each depth's nodes (depth 0: the level's bricks) are stored
     * contiguously, x fastest (docs/format.md), and ip_store_node_range() would otherwise
     * sum the grids of the shallower depths on every lookup. */
    const ip_level_layout *lv = &s->layout->levels[s->level];
    static const uint32_t origin[3] = {0, 0, 0};
    for (uint32_t depth = 0; depth <= lv->octree_depth && depth <= IP_SEED_MAX_DEPTH; depth++) {
        ip__octree_grid(s->layout, s->level, depth, s->grid[depth]);
        s->ranges[depth] = ip_store_node_range(s->store, s->level, depth, origin);
    }
    s->first_brick = lv->first_brick;
    ip__seeder_band(s, 0.0, INFINITY);
}

void ip__seeder_band(ip_seeder *s, double near, double far)
{
    s->band_near = near;
    s->band_far = far;
    s->banded = near > 0.0 || far < INFINITY;
}

/* The ray eye + t * dir in the index space of a level whose cells are `scale` world units. */
static void index_ray_init(index_ray *r, const double scale[3], const double eye[3],
                           const double dir[3])
{
    for (int k = 0; k < 3; k++) {
        r->origin[k] = eye[k] / scale[k];
        r->dir[k] = dir[k] / scale[k];
        r->inv_dir[k] = r->dir[k] != 0.0 ? 1.0 / r->dir[k] : 0.0;
    }
    r->len = fmax(fabs(r->dir[0]), fmax(fabs(r->dir[1]), fabs(r->dir[2])));
    r->world_origin = eye;
    r->world_dir = dir;
}

/* 1 when the ray crosses, between t0 and t1, a sub-block of brick g (of `level`, coordinates
 * b) whose range holds the isovalue. */
static int brick_crossed_active(const ip_store *store, uint32_t level, float iso,
                                const index_ray *r, uint64_t g, const uint32_t b[3], double t0,
                                double t1)
{
    const ip_layout *l = ip_store_layout(store);
    uint32_t origin[3], extent[3], n[3], se = l->subblock_edge, per = l->brick_edge / se;
    ip_brick_extent(l, level, b, origin, extent);
    for (int k = 0; k < 3; k++)
        n[k] = (extent[k] - 1 + se - 1) / se;
    const float *ranges = ip_store_subblock_ranges(store, g);
    double base[3] = {origin[0], origin[1], origin[2]};
    dda d;
    dda_init(&d, r, base, se, n, t0, t1);
    for (;;) {
        uint32_t sb = (uint32_t)d.i[0] + per * ((uint32_t)d.i[1] + per * (uint32_t)d.i[2]);
        if (active(&ranges[2 * sb], iso))
            return 1;
        double exit_t;
        if (!dda_next(&d, &exit_t))
            return 0;
    }
}

unsigned ip__seed_ray_bricks(const ip_store *store, uint32_t level, float iso,
                             const ip_clip *planes, const double eye[3], const double dir[3],
                             double t_min, double t_max, uint64_t *bricks, unsigned max)
{
    const ip_layout *l = ip_store_layout(store);
    const ip_level_layout *lv = &l->levels[level];
    double scale[3], lo[3] = {0, 0, 0}, hi[3], t0 = t_min, t1 = t_max;
    index_ray r;
    for (int k = 0; k < 3; k++) {
        scale[k] = l->spacing[k] * (double)(1u << level);
        hi[k] = (double)(lv->dims[k] - 1);
    }
    index_ray_init(&r, scale, eye, dir);
    unsigned count = 0;
    if (max == 0 || !clip(&r, lo, hi, &t0, &t1))
        return 0;
    dda d;
    dda_init(&d, &r, lo, l->brick_edge, lv->bricks, t0, t1);
    for (;;) {
        uint32_t b[3] = {(uint32_t)d.i[0], (uint32_t)d.i[1], (uint32_t)d.i[2]};
        double enter_t = d.t, exit_t;
        int more = dda_next(&d, &exit_t);
        uint64_t g = ip_brick_global_index(l, level, b);
        float range[2];
        ip_store_brick_range(store, g, range);
        if (active(range, iso) && ip__clip_keeps_brick(planes, l, g) &&
            brick_crossed_active(store, level, iso, &r, g, b, enter_t, exit_t)) {
            bricks[count++] = g;
            if (count == max)
                return count;
        }
        if (!more)
            return count;
    }
}

int ip__seed_find(ip_seeder *s, const double eye[3], const double dir[3], double t_min,
                  double t_max, uint32_t cells[][3], unsigned *count, int *seed_index)
{
    s->found = cells;
    s->found_count = 0;
    s->seed_index = -1;
    s->hit_t = INFINITY;
    *count = 0;
    *seed_index = -1;
    const ip_level_layout *lv = &s->layout->levels[s->level];
    uint32_t root[3] = {0, 0, 0};
    uint32_t depth = lv->octree_depth;
    if (!active(s->ranges[depth], s->iso))
        return 0;
    index_ray r;
    index_ray_init(&r, s->scale, eye, dir);
    across_basis(dir, r.u, r.w);
    double lo[3], hi[3], t0 = t_min, t1 = t_max;
    ip__seeder_node_box(s, depth, root, lo, hi);
    /* The ray's reach (seed.h), from its farthest point within a cell of the volume. */
    double wide_lo[3], wide_hi[3], w0 = t_min, w1 = t_max;
    for (int k = 0; k < 3; k++) {
        wide_lo[k] = lo[k] - 1.0;
        wide_hi[k] = hi[k] + 1.0;
    }
    if (!clip(&r, wide_lo, wide_hi, &w0, &w1))
        return 0;
    s->within_most = 0.0;
    for (int k = 0; k < 3; k++) {
        s->reach[k] = s->thick * w1 / s->scale[k];
        s->within[k] = r.dir[k] != 0.0 ? s->reach[k] / fabs(r.dir[k]) : 0.0;
        s->within_most = s->within[k] > s->within_most ? s->within[k] : s->within_most;
    }
    int enter_axis = -1, leave_axis = -1, found = 0; /* clip_axes() sets them when inside */
    int inside = clip_axes(&r, lo, hi, &t0, &t1, &enter_axis, &leave_axis);
    /* Where the ray runs outside the volume, it may pass close to cells on its faces. */
    static const double none_lo[3] = {INFINITY, INFINITY, INFINITY},
                        none_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    static const uint32_t cells_lo[3] = {0, 0, 0};
    uint32_t cells_hi[3] = {lv->dims[0] - 1, lv->dims[1] - 1, lv->dims[2] - 1};
    /* Entering squarely through a face, the ray is within reach of cells outside the one it
     * enters only where it moves into another cell within reach of that face (as
     * near_faces()); missing the volume, anywhere it passes within reach of it. */
    int outside_before =
        !inside || enter_axis < 0 ||
        changes_cell(&r, enter_axis, t0 - s->within[enter_axis], t0 + s->within[enter_axis]);
    double before = inside ? t0 : w1;
    if (w0 < before && outside_before)
        found = near_cells(s, &r, wide_lo, wide_hi, none_lo, none_hi, cells_lo, cells_hi, w0,
                           before, -1, -1);
    if (inside && found == 0)
        found = (t1 - t0) * r.len <= s->short_walk * s->layout->brick_edge
                    ? walk_bricks(s, &r, t0, t1)
                    : walk_node(s, &r, depth, root, t0, t1);
    if (inside && found == 0 && t1 < w1 &&
        (leave_axis < 0 ||
         changes_cell(&r, leave_axis, t1 - s->within[leave_axis], t1 + s->within[leave_axis])))
        found = near_cells(s, &r, wide_lo, wide_hi, none_lo, none_hi, cells_lo, cells_hi, t1, w1,
                           -1, -1);
    if (found < 0)
        return -1; /* a brick could not be read: the cells found so far may be wrong */
    *count = s->found_count;
    *seed_index = s->seed_index;
    return found || s->seed_index >= 0;
}
