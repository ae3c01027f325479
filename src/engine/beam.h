/* SPDX-License-Identifier: BSD-3-Clause */
/* Beams: whether the rays through a screen tile could still extract anything, tested once for
 * the whole tile against the min/max octree (bulk retirement of rays; see retire.c). Internal. */
#ifndef ISOPROP_BEAM_H
#define ISOPROP_BEAM_H

#include "seed.h"
#include "visited.h"

/* The rays from `eye` through a convex screen region, as the 4 planes through the eye that
 * bound them (world units, normals pointing inwards), and a depth beyond which they need not
 * look: a point lies in the beam when it is on the inner side of every plane. */
typedef struct ip_beam {
    double eye[3];
    double normal[4][3];
    double forward[3];   /* the view direction (unit) */
    double corner[4][3]; /* the corner directions (unit) */
    double max_depth;    /* view depth (world units): cells wholly beyond it are passed over */
    double min_depth;    /* and those wholly nearer than this, known settled (-infinity: none) */
} ip_beam;

/* The beam of the rays from the eye through the four corner directions `corner` (unit, in
 * order around the region, each ray of the region a positive combination of them), with
 * min_depth -infinity. */
void ip__beam_init(ip_beam *b, const double eye[3], const double forward[3],
                   const double corner[4][3], double max_depth);

/* 1 when every active cell of the seeder's level (a marching-cubes case other than 0 and
 * 255) that the clipping planes keep, that the beam may cross and whose nearest point lies
 * no deeper than b->max_depth is marked in `visited` (*settled_to = b->max_depth then); 0
 * when some may not be, with *settled_to a view depth (world units) short of which the beam
 * is settled: every such cell that may not be marked lies wholly deeper. The test goes on past
 * the first such cell, nearest first, looking only nearer than the nearest found so far. Reads
 * the summaries, and where an active sub-block meets the beam the cells of its brick, only if
 * the cache already holds it (ip__sampler_resident_cell_brick(): the sub-block of a brick not
 * resident counts as not settled, and nothing is read). Conservative: boxes are tested against
 * the beam's planes one at a time, so some that miss it count as met. Records in `visited`
 * the sub-blocks and cell groups it finds wholly visited (ip__visited_mark_part()), which
 * later tests pass over. */
int ip__beam_settled(ip_seeder *s, ip_visited *visited, const ip_beam *b, double *settled_to);

#endif
