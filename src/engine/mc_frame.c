/* SPDX-License-Identifier: BSD-3-Clause */
/* Marching cubes in the volume's physical frame: the triangle table turned by the cube symmetry
 * between a cell's world corners and its corners in the canonical frame (mc.h, "Frames"). */
#include <math.h>
#include <string.h>

#include "mc.h"

/* The file's directions in the canonical frame: LPS for a named space, the physical frame
 * otherwise. column[a] is world axis a's direction. */
static void canonical_columns(const ip_orientation *o, double column[3][3])
{
    /* the signs that take each space's x and y to LPS's */
    double sx = o->space == IP_SPACE_RAS ? -1.0 : 1.0;
    double sy = o->space == IP_SPACE_RAS || o->space == IP_SPACE_LAS ? -1.0 : 1.0;
    for (int a = 0; a < 3; a++) {
        column[a][0] = sx * o->directions[a][0];
        column[a][1] = sy * o->directions[a][1];
        column[a][2] = o->directions[a][2];
    }
}

int ip__mc_frame_of(const ip_orientation *o, ip_mc_frame *f)
{
    double column[3][3];
    canonical_columns(o, column);
    unsigned taken = 0;
    int identity = 1;
    for (int a = 0; a < 3; a++) {
        /* the canonical axis world axis a runs along most, of those not taken yet */
        int best = -1;
        for (int c = 0; c < 3; c++)
            if (!(taken >> c & 1u) && (best < 0 || fabs(column[a][c]) > fabs(column[a][best])))
                best = c;
        taken |= 1u << best;
        f->axis[a] = (uint8_t)best;
        f->flip[a] = column[a][best] < 0;
        identity &= best == a && !f->flip[a];
    }
    return identity;
}

/* The world corner of canonical corner k: world axis a's bit is canonical axis axis[a]'s,
 * flipped where the axes run opposite ways. */
static unsigned world_corner(const ip_mc_frame *f, unsigned k)
{
    unsigned j = 0;
    for (unsigned a = 0; a < 3; a++)
        j |= ((k >> f->axis[a] & 1u) ^ f->flip[a]) << a;
    return j;
}

/* The edge joining corners i and j (neighbours). */
static int8_t edge_between(unsigned i, unsigned j)
{
    for (int8_t e = 0; e < 12; e++) {
        unsigned a = ip__mc_edge_corners[e][0], b = ip__mc_edge_corners[e][1];
        if ((a == i && b == j) || (a == j && b == i))
            return e;
    }
    return -1; /* not reached: corners of one edge stay neighbours */
}

/* 1 when the frame turns the cell's handedness over (an odd number of flips and swaps). */
static int reflects(const ip_mc_frame *f)
{
    int odd = f->flip[0] ^ f->flip[1] ^ f->flip[2];
    /* a permutation of three is odd when it fixes exactly one axis */
    int fixed = (f->axis[0] == 0) + (f->axis[1] == 1) + (f->axis[2] == 2);
    return odd ^ (fixed == 1);
}

void ip__mc_frame_rows(const ip_mc_frame *f, int8_t rows[256][16])
{
    unsigned corner[8];
    int8_t edge[12];
    for (unsigned k = 0; k < 8; k++)
        corner[k] = world_corner(f, k);
    for (unsigned e = 0; e < 12; e++)
        edge[e] =
            edge_between(corner[ip__mc_edge_corners[e][0]], corner[ip__mc_edge_corners[e][1]]);
    int swap = reflects(f);
    for (unsigned c = 0; c < 256; c++) {
        unsigned canonical = 0; /* the case the cell has in the canonical frame */
        for (unsigned k = 0; k < 8; k++)
            canonical |= (c >> corner[k] & 1u) << k;
        const int8_t *from = ip__mc_triangle_table[canonical];
        int count = ip__mc_triangle_count[canonical];
        memset(rows[c], -1, sizeof rows[c]);
        for (int t = 0; t < count; t++) {
            /* counter-clockwise from outside in world space too: a reflection turns it over */
            rows[c][3 * t] = edge[from[3 * t]];
            rows[c][3 * t + 1] = edge[from[3 * t + (swap ? 2 : 1)]];
            rows[c][3 * t + 2] = edge[from[3 * t + (swap ? 1 : 2)]];
        }
    }
}
