/* SPDX-License-Identifier: BSD-3-Clause */
/* Beams against the min/max octree: root -> bricks -> sub-blocks -> cell groups -> cells. */
#include <math.h>

#include "beam.h"
#include "format.h"
#include "internal.h"
#include "lod.h"
#include "vec3.h"

/* The beam in the level's index space (cell (i, j, k) is the box [i, i+1] x ...): a box meets
 * it unless it lies wholly beyond max_depth or wholly outside one plane. */
typedef struct index_beam {
    ip_seeder *s;
    ip_visited *visited;
    double normal[4][3];     /* the planes' normals with index coordinates: n[a] * scale[a] */
    double offset[4];        /* - n . eye */
    double forward[3];       /* forward[a] * scale[a] */
    double limit;            /* max_depth + forward . eye, lowered below each box found unsettled */
    double floor;            /* min_depth + forward . eye */
    int flip;                /* bit a: forward[a] < 0 (the nearer half along axis a is the high) */
    double eye[3];           /* the eye, in index coordinates */
    double step[4][3];       /* along corner ray i, index units per unit of view depth */
    double at_eye;           /* forward . eye (world) */
    const double *world_eye; /* the eye (world units), for the seeder's distance band */
} index_beam;

void ip__beam_init(ip_beam *b, const double eye[3], const double forward[3],
                   const double corner[4][3], double max_depth)
{
    double middle[3] = {0, 0, 0};
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++)
            middle[a] += corner[i][a];
    for (int i = 0; i < 4; i++) {
        ip__vec3_cross(corner[i], corner[(i + 1) % 4], b->normal[i]);
        if (ip__vec3_dot(b->normal[i], middle) < 0)
            for (int a = 0; a < 3; a++)
                b->normal[i][a] = -b->normal[i][a];
    }
    for (int a = 0; a < 3; a++) {
        b->eye[a] = eye[a];
        b->forward[a] = forward[a];
    }
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++)
            b->corner[i][a] = corner[i][a];
    b->max_depth = max_depth;
    b->min_depth = -INFINITY;
}

/* The part of the beam between view depths z0 and z1 (0 <= z0 <= z1) lies within the convex
 * hull of the 8 points where its corner rays cross those depths: its bounding box, in index
 * coordinates, in [lo, hi]. */
static void slice_box(const index_beam *w, double z0, double z1, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
        for (int i = 0; i < 4; i++)
            for (int e = 0; e < 2; e++) {
                double v = w->eye[a] + w->step[i][a] * (e ? z1 : z0);
                lo[a] = v < lo[a] ? v : lo[a];
                hi[a] = v > hi[a] ? v : hi[a];
            }
    }
}

/* The index box [lo, hi]'s nearest point's forward . p (its view depth + forward . eye). */
static inline double nearest(const index_beam *w, const double lo[3], const double hi[3])
{
    double z = 0;
    for (int a = 0; a < 3; a++)
        z += w->forward[a] * (w->forward[a] >= 0 ? lo[a] : hi[a]);
    return z;
}

/* The index box [lo, hi]'s farthest point's forward . p. */
static inline double farthest(const index_beam *w, const double lo[3], const double hi[3])
{
    return nearest(w, hi, lo);
}

/* 1 when the index box [lo, hi] may meet the beam. */
static inline int meets(const index_beam *w, const double lo[3], const double hi[3])
{
    if (nearest(w, lo, hi) > w->limit || farthest(w, lo, hi) < w->floor)
        return 0;
    for (int p = 0; p < 4; p++) {
        const double *n = w->normal[p];
        double v = w->offset[p];
        for (int a = 0; a < 3; a++)
            v += n[a] * (n[a] >= 0 ? hi[a] : lo[a]);
        if (v < 0)
            return 0;
    }
    return 1;
}

/* 1 when no cell of the index box [lo, hi] can be the view's at the seeder's level: with
 * adaptive resolution, every point of the box (scaled to world units: the centres of its cells
 * included) lies outside the level's distance band (lod.h), by a margin for rounding. */
static int outside_band(const index_beam *w, const double lo[3], const double hi[3])
{
    const ip_seeder *s = w->s;
    if (!s->banded)
        return 0;
    double wlo[3], whi[3];
    for (int a = 0; a < 3; a++) {
        wlo[a] = lo[a] * s->scale[a];
        whi[a] = hi[a] * s->scale[a];
    }
    return ip__lod_box_outside(wlo, whi, w->world_eye, s->band_near * (1 - 1e-9),
                               s->band_far * (1 + 1e-9));
}

/* The index box [lo, hi], met by the beam, may hold an active cell that is not visited: the
 * beam is settled only short of its nearest point from now on, and boxes wholly beyond that
 * are passed over. */
static void unsettled(index_beam *w, const double lo[3], const double hi[3])
{
    double z = nextafter(nearest(w, lo, hi), -INFINITY);
    w->limit = z < w->limit ? z : w->limit;
}

/* Bit i set when sample first + i (i < n <= IP_CELL_GROUP + 1) of brick b is at or above iso:
 * a corner bit of ip__mc_case() (a NaN is below). */
static unsigned row_at_or_above(const ip_brick *b, ip_type type, size_t first, unsigned n,
                                float iso)
{
    _Static_assert(IP_CELL_GROUP == 4, "one offset per sample of a group's row");
    static const ptrdiff_t along[IP_CELL_GROUP + 1] = {0, 1, 2, 3, 4};
    float v[IP_CELL_GROUP + 1] = {0}; /* all written below: the compiler cannot tell */
    ip__samples_gather(b->samples, type, first, along, (int)n, v);
    unsigned bits = 0;
    for (unsigned i = 0; i < n; i++)
        bits |= (unsigned)(v[i] >= iso) << i;
    return bits;
}

/* The active cells (ip__mc_case() neither 0 nor 255) among cells [g0, g1) of brick b, at most
 * IP_CELL_GROUP a side: bit x - g0[0] of active[z - g0[2]][y - g0[1]]. Each sample is
 * classified once, into a bit of its row along x, rather than once per cell it is a corner of:
 * a cell is active where its 4 corner rows have, at its two bits, some set and not all. */
static void group_active(const ip_brick *b, ip_type type, const uint32_t g0[3],
                         const uint32_t g1[3], float iso,
                         unsigned active[IP_CELL_GROUP][IP_CELL_GROUP])
{
    unsigned rows[IP_CELL_GROUP + 1][IP_CELL_GROUP + 1];
    unsigned nx = g1[0] - g0[0], ny = g1[1] - g0[1], nz = g1[2] - g0[2];
    size_t row = b->extent[0], slice = row * b->extent[1], first = ip__sample_index(b, g0);
    for (unsigned z = 0; z <= nz; z++)
        for (unsigned y = 0; y <= ny; y++)
            rows[z][y] = row_at_or_above(b, type, first + y * row + z * slice, nx + 1, iso);
    unsigned cells = (1u << nx) - 1;
    for (unsigned z = 0; z < nz; z++)
        for (unsigned y = 0; y < ny; y++) {
            unsigned all = rows[z][y] & rows[z][y + 1] & rows[z + 1][y] & rows[z + 1][y + 1];
            unsigned any = rows[z][y] | rows[z][y + 1] | rows[z + 1][y] | rows[z + 1][y + 1];
            active[z][y] = (any | any >> 1) & ~(all & all >> 1) & cells;
        }
}

/* The cells [lo, hi) of sub-block `sb` (index within its brick), by cell groups (cache.h):
 * those that are active and not visited lower the beam's limit (unsettled()). A cell group the
 * beam meets every active cell of which is visited is recorded as settled
 * (ip__visited_mark_part()), and so is
 * a sub-block all of whose groups are (or hold no active cell); later tests pass over them
 * at once: cells once visited stay so. Groups are recorded only where sub-blocks hold whole
 * groups; the groups the beam does not meet are not looked at. */
static void settled_cells(index_beam *w, const uint32_t lo[3], const uint32_t hi[3], int side,
                          uint32_t sb)
{
    ip_seeder *s = w->s;
    /* only a brick the view has already loaded: a beam wider and deeper than its rays must not
     * read bricks they would never read (not settled then: the rays walk) */
    const ip_brick *brick = ip__sampler_resident_cell_brick(s->sampler, lo);
    if (!brick) {
        double blo[3] = {lo[0], lo[1], lo[2]}, bhi[3] = {hi[0], hi[1], hi[2]};
        unsettled(w, blo, bhi);
        return;
    }
    const atomic_uint_fast64_t *marked = ip__visited_bitmap(w->visited, brick->index);
    if (ip__visited_part_in(w->visited, marked, sb))
        return;
    uint32_t per_group = (s->layout->brick_edge + IP_CELL_GROUP - 1) / IP_CELL_GROUP;
    int record_groups = s->layout->subblock_edge >= IP_CELL_GROUP;
    size_t groups_x = ip_cell_groups(brick->extent[0]),
           groups_xy = groups_x * ip_cell_groups(brick->extent[1]);
    int whole = 1; /* no active cell of the sub-block unvisited so far */
    /* the groups the sub-block meets, each clipped to it: [g0, g1) */
    uint32_t first[3];
    for (int k = 0; k < 3; k++)
        first[k] = lo[k] - (lo[k] - brick->origin[k]) % IP_CELL_GROUP;
    for (uint32_t gz = first[2]; gz < hi[2]; gz += IP_CELL_GROUP)
        for (uint32_t gy = first[1]; gy < hi[1]; gy += IP_CELL_GROUP)
            for (uint32_t gx = first[0]; gx < hi[0]; gx += IP_CELL_GROUP) {
                uint32_t g[3] = {gx, gy, gz}, g0[3], g1[3];
                for (int k = 0; k < 3; k++) {
                    g0[k] = g[k] > lo[k] ? g[k] : lo[k];
                    g1[k] = g[k] + IP_CELL_GROUP < hi[k] ? g[k] + IP_CELL_GROUP : hi[k];
                }
                uint32_t gi[3] = {(gx - brick->origin[0]) / IP_CELL_GROUP,
                                  (gy - brick->origin[1]) / IP_CELL_GROUP,
                                  (gz - brick->origin[2]) / IP_CELL_GROUP};
                uint64_t part = w->visited->subblocks_per_brick + gi[0] +
                                per_group * (gi[1] + (uint64_t)per_group * gi[2]);
                if (record_groups && ip__visited_part_in(w->visited, marked, part))
                    continue;
                if (s->use_group_ranges) {
                    static const ptrdiff_t pair[2] = {0, 1};
                    float range[2];
                    size_t at = gi[0] + groups_x * gi[1] + groups_xy * gi[2];
                    ip__samples_gather(brick->group_ranges, s->layout->type, 2 * at, pair, 2,
                                       range);
                    if (!ip__range_active(range[0], range[1], s->iso))
                        continue;
                }
                double blo[3] = {g0[0], g0[1], g0[2]}, bhi[3] = {g1[0], g1[1], g1[2]};
                if (!meets(w, blo, bhi)) {
                    whole = 0; /* not looked at: the sub-block is not known to be whole */
                    continue;
                }
                int group_whole = 1;
                unsigned active[IP_CELL_GROUP][IP_CELL_GROUP];
                group_active(brick, s->layout->type, g0, g1, s->iso, active);
                for (uint32_t z = g0[2]; z < g1[2]; z++)
                    for (uint32_t y = g0[1]; y < g1[1]; y++)
                        for (unsigned left = active[z - g0[2]][y - g0[1]]; left; left &= left - 1) {
                            uint32_t x = g0[0] + ip__lowest_bit(left);
                            uint32_t c[3] = {x, y, z}, c1[3] = {x + 1, y + 1, z + 1};
                            if (ip__visited_test_in(w->visited, marked, c))
                                continue;
                            if (side != IP__CLIP_KEEPS_ALL &&
                                !ip__clip_keeps_samples(&s->clip, s->layout, s->level, c, c1))
                                continue;
                            if (s->banded && !ip__lod_cell_in_band(s->sampler, c, w->world_eye,
                                                                   s->band_near, s->band_far))
                                continue; /* never the view's: as the rays and propagation */
                            whole = group_whole = 0;
                            double clo[3] = {x, y, z}, chi[3] = {x + 1.0, y + 1.0, z + 1.0};
                            if (meets(w, clo, chi))
                                unsettled(w, clo, chi);
                        }
                if (group_whole && record_groups) /* out of memory: not recorded, no harm */
                    (void)ip__visited_mark_part(w->visited, brick->index, part);
            }
    if (whole)
        (void)ip__visited_mark_part(w->visited, brick->index, sb);
}

/* The sub-blocks of brick `b` (its index box [box_lo, box_hi]) within the bounding box of the
 * beam's part between the brick's nearest and farthest depths, nearest first along each axis. */
static void settled_brick(index_beam *w, const uint32_t b[3], const double box_lo[3],
                          const double box_hi[3])
{
    ip_seeder *s = w->s;
    const ip_layout *l = s->layout;
    uint32_t origin[3], extent[3], n[3];
    const float *ranges = ip__seeder_brick(s, b, origin, extent, n);
    uint32_t per = l->brick_edge / l->subblock_edge, first[3], last[3];
    double z0 = nearest(w, box_lo, box_hi) - w->at_eye, z1 = w->limit - w->at_eye,
           far = farthest(w, box_lo, box_hi) - w->at_eye;
    z0 = z0 > 0 ? z0 : 0;
    z1 = z1 < far ? z1 : far;
    if (!(z0 <= z1))
        return;
    double slo[3], shi[3];
    slice_box(w, z0, z1, slo, shi);
    for (int a = 0; a < 3; a++) {
        double se = l->subblock_edge, f = floor((slo[a] - origin[a]) / se - 1e-9),
               e = floor((shi[a] - origin[a]) / se + 1e-9);
        if (!(e >= 0) || !(f < n[a])) /* the box misses the brick (or is not a number) */
            return;
        first[a] = f > 0 ? (uint32_t)f : 0;
        last[a] = e < n[a] - 1.0 ? (uint32_t)e : n[a] - 1;
    }
    for (uint32_t ii = first[2]; ii <= last[2]; ii++)
        for (uint32_t jj = first[1]; jj <= last[1]; jj++)
            for (uint32_t hh = first[0]; hh <= last[0]; hh++) {
                uint32_t h = w->flip & 1 ? first[0] + last[0] - hh : hh,
                         j = w->flip & 2 ? first[1] + last[1] - jj : jj,
                         i = w->flip & 4 ? first[2] + last[2] - ii : ii;
                uint32_t sb = h + per * (j + per * i), at[3] = {h, j, i};
                if (!ip__range_active(ranges[2 * sb], ranges[2 * sb + 1], s->iso))
                    continue;
                uint32_t lo[3], hi[3];
                ip__seeder_subblock_cells(s, origin, extent, at, lo, hi);
                double blo[3] = {lo[0], lo[1], lo[2]}, bhi[3] = {hi[0], hi[1], hi[2]};
                if (!meets(w, blo, bhi) || outside_band(w, blo, bhi))
                    continue;
                int side = ip__clip_keeps_samples(&s->clip, l, s->level, lo, hi);
                if (side)
                    settled_cells(w, lo, hi, side, sb);
            }
}

/* Node `node` of octree depth `depth` (0: a brick), which meets the beam: its children,
 * nearest first along each axis, so that the limit falls early. */
static void settled_node(index_beam *w, uint32_t depth, const uint32_t node[3])
{
    if (depth == 0) {
        double lo[3], hi[3];
        ip__seeder_node_box(w->s, 0, node, lo, hi);
        settled_brick(w, node, lo, hi);
        return;
    }
    ip_seeder *s = w->s;
    for (int i = 0; i < 8; i++) {
        int c = i ^ w->flip;
        uint32_t ch[3];
        if (!ip__seeder_active_child(s, depth, node, c, ch))
            continue;
        double lo[3], hi[3];
        ip__seeder_node_box(s, depth - 1, ch, lo, hi);
        if (!meets(w, lo, hi) || outside_band(w, lo, hi) || !ip__seeder_node_kept(s, depth - 1, ch))
            continue;
        settled_node(w, depth - 1, ch);
    }
}

int ip__beam_settled(ip_seeder *s, ip_visited *visited, const ip_beam *b, double *settled_to)
{
    index_beam w;
    w.s = s;
    w.visited = visited;
    double at_eye = ip__vec3_dot(b->forward, b->eye);
    w.at_eye = at_eye;
    w.world_eye = b->eye;
    for (int i = 0; i < 4; i++) {
        double cosine = ip__vec3_dot(b->corner[i], b->forward);
        for (int a = 0; a < 3; a++)
            w.step[i][a] = b->corner[i][a] / cosine / s->scale[a];
    }
    for (int a = 0; a < 3; a++)
        w.eye[a] = b->eye[a] / s->scale[a];
    w.limit = b->max_depth + at_eye;
    w.floor = b->min_depth + at_eye;
    double limit = w.limit;
    *settled_to = b->max_depth;
    w.flip = 0;
    for (int a = 0; a < 3; a++) {
        w.forward[a] = b->forward[a] * s->scale[a];
        w.flip |= (b->forward[a] < 0) << a;
    }
    for (int p = 0; p < 4; p++) {
        w.offset[p] = -ip__vec3_dot(b->normal[p], b->eye);
        for (int a = 0; a < 3; a++)
            w.normal[p][a] = b->normal[p][a] * s->scale[a];
    }
    const ip_level_layout *lv = &s->layout->levels[s->level];
    uint32_t depth = lv->octree_depth;
    if (!ip__range_active(s->ranges[depth][0], s->ranges[depth][1], s->iso))
        return 1;
    static const uint32_t root[3] = {0, 0, 0};
    double lo[3], hi[3];
    ip__seeder_node_box(s, depth, root, lo, hi);
    if (!meets(&w, lo, hi) || outside_band(&w, lo, hi))
        return 1;
    settled_node(&w, depth, root);
    if (w.limit == limit)
        return 1;
    *settled_to = w.limit - at_eye;
    return 0;
}
