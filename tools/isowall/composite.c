/* SPDX-License-Identifier: BSD-3-Clause */
/* Compositing the wall: per display tile, the processes whose triangles reach it draw them
 * (depth and colour) and send the rectangle of the pixels they cover to the tile's owner,
 * which keeps the nearest surface of each pixel (direct send; ties go to the lower rank, so the
 * result does not depend on timing). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "composite.h"
#include "watch.h"

double wall_cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A tile as drawn: inverse depths (doubles, 0 where empty), then the colours (4 bytes a
 * pixel). */
static size_t tile_bytes(size_t pixels)
{
    return pixels * (sizeof(double) + 4);
}

/* A tile as sent: the rectangle of the pixels the sender's triangles cover, as four uint32
 * (x, y, width, height within the tile; 0 x 0 when none), then its inverse depths and colours
 * as in a drawn tile. Returns the bytes packed into `out` (room for HEADER + tile_bytes()). */
enum {
    HEADER = 4 * sizeof(uint32_t)
};

static size_t pack_covered(const uint8_t *tile, uint32_t tile_w, uint32_t tile_h, uint8_t *out)
{
    const double *depth = (const double *)tile;
    const uint8_t *rgba = tile + (size_t)tile_w * tile_h * sizeof(double);
    uint32_t x0 = tile_w, y0 = tile_h, x1 = 0, y1 = 0;
    for (uint32_t y = 0; y < tile_h; y++)
        for (uint32_t x = 0; x < tile_w; x++)
            if (depth[(size_t)y * tile_w + x] > 0) {
                x0 = x < x0 ? x : x0, x1 = x + 1 > x1 ? x + 1 : x1;
                y0 = y < y0 ? y : y0, y1 = y + 1 > y1 ? y + 1 : y1;
            }
    uint32_t header[4] = {x0, y0, x1 > x0 ? x1 - x0 : 0, y1 > y0 ? y1 - y0 : 0};
    memcpy(out, header, HEADER);
    size_t n = (size_t)header[2] * header[3];
    uint8_t *out_depth = out + HEADER, *out_rgba = out_depth + n * sizeof(double);
    for (uint32_t y = 0; y < header[3]; y++) {
        size_t from = (size_t)(y0 + y) * tile_w + x0, to = (size_t)y * header[2];
        memcpy(out_depth + to * sizeof(double), depth + from, header[2] * sizeof(double));
        memcpy(out_rgba + 4 * to, rgba + 4 * from, 4 * (size_t)header[2]);
    }
    return HEADER + n * (sizeof(double) + 4);
}

/* A rectangle of drawn pixels to merge into a tile: at (x, y) within it, rows `stride` pixels
 * apart in depth (doubles, maybe unaligned) and rgba. */
typedef struct piece {
    uint32_t x, y, width, height, stride;
    const uint8_t *depth, *rgba;
} piece;

/* The rectangle that pack_covered() packed. */
static piece unpacked(const uint8_t *packed)
{
    uint32_t h[4];
    memcpy(h, packed, HEADER);
    const uint8_t *depth = packed + HEADER;
    return (piece){
        h[0], h[1], h[2], h[3], h[2], depth, depth + (size_t)h[2] * h[3] * sizeof(double)};
}

/* The whole of a drawn tile (tile_bytes()). */
static piece whole(const uint8_t *tile, uint32_t tile_w, uint32_t tile_h)
{
    return (piece){
        0, 0, tile_w, tile_h, tile_w, tile, tile + (size_t)tile_w * tile_h * sizeof(double)};
}

/* Keeps, per pixel of the piece, the nearer of `into` (a drawn tile) and the piece's pixel
 * (strictly nearer: on equal depth the earlier contribution stays). */
static void keep_nearest(uint8_t *into, uint32_t tile_w, uint32_t tile_h, piece p)
{
    double *depth = (double *)into;
    uint8_t *rgba = into + (size_t)tile_w * tile_h * sizeof(double);
    for (uint32_t y = 0; y < p.height; y++)
        for (uint32_t x = 0; x < p.width; x++) {
            size_t i = (size_t)y * p.stride + x, j = (size_t)(p.y + y) * tile_w + p.x + x;
            double d;
            memcpy(&d, p.depth + i * sizeof(double), sizeof d);
            if (d > depth[j]) {
                depth[j] = d;
                memcpy(rgba + 4 * j, p.rgba + 4 * i, 4);
            }
        }
}

/* Draws the rank's mesh into tile t (depth, colour) into buf. Returns 0 or -1. */
static int draw_tile(wall_composite *c, uint32_t t, const ip_mesh *mesh, uint8_t *buf,
                     ip_error *err)
{
    const wall_layout *w = c->layout;
    uint32_t col = t % w->cols, row = t / w->cols;
    size_t pixels = (size_t)w->tile_w * w->tile_h;
    double start = wall_cpu_seconds();
    wall_watch_stage("drawing tile %u for the composite", t);
    ip_status st = ip_raster_mesh_part(mesh, &w->camera, c->shading, w->lo, w->hi, col * w->tile_w,
                                       row * w->tile_h, w->tile_w, w->tile_h, (double *)buf,
                                       buf + pixels * sizeof(double), err);
    c->busy_seconds += wall_cpu_seconds() - start;
    return st == IP_OK ? 0 : -1;
}

/* The background of tile t into buf, depth 0: the renderer's colours of the tile's first column
 * (the background varies by row only), repeated along each row. Returns 0 or -1. */
static int fill_background(wall_composite *c, uint32_t t, uint8_t *buf, uint8_t *column,
                           ip_error *err)
{
    const wall_layout *w = c->layout;
    size_t pixels = (size_t)w->tile_w * w->tile_h;
    double start = wall_cpu_seconds();
    ip_mesh empty;
    ip_mesh_init(&empty);
    ip_status st =
        ip_raster_mesh_part(&empty, &w->camera, c->shading, w->lo, w->hi, t % w->cols * w->tile_w,
                            t / w->cols * w->tile_h, 1, w->tile_h, NULL, column, err);
    memset(buf, 0, pixels * sizeof(double));
    uint8_t *rgba = buf + pixels * sizeof(double);
    for (uint32_t y = 0; st == IP_OK && y < w->tile_h; y++)
        for (uint32_t x = 0; x < w->tile_w; x++)
            memcpy(rgba + 4 * ((size_t)y * w->tile_w + x), column + 4 * (size_t)y, 4);
    c->busy_seconds += wall_cpu_seconds() - start;
    return st == IP_OK ? 0 : -1;
}

int wall_composite_run(wall_composite *c, const ip_mesh *mesh, wall_tile_done *done, void *user,
                       ip_error *err)
{
    const wall_layout *w = c->layout;
    int ranks = c->ranks, me = c->rank;
    size_t pixels = (size_t)w->tile_w * w->tile_h, bytes = tile_bytes(pixels);
    uint8_t *mine = calloc(w->tile_count, 1), *all = malloc((size_t)w->tile_count * ranks);
    uint8_t *result = malloc(bytes), *own = malloc(bytes), *packed = malloc(HEADER + bytes);
    uint8_t *column = malloc(4 * (size_t)w->tile_h);
    int rc = mine && all && result && own && packed && column ? 0 : -1;
    if (rc != 0) { /* the caller ends the job */
        err->code = IP_ERR_NOMEM;
        snprintf(err->message, sizeof err->message, "out of memory for a %ux%u tile", w->tile_w,
                 w->tile_h);
        goto out;
    }
    double start = wall_cpu_seconds();
    wall_touched_tiles(w, mesh, mine);
    c->busy_seconds += wall_cpu_seconds() - start;
    /* every rank learns who draws what (one byte per tile and rank) */
    double wait = MPI_Wtime();
    wall_watch_stage("learning which process draws which tile at the composite");
    MPI_Allgather(mine, (int)w->tile_count, MPI_BYTE, all, (int)w->tile_count, MPI_BYTE,
                  MPI_COMM_WORLD);
    c->idle_seconds += MPI_Wtime() - wait;
    c->bytes_sent += (uint64_t)w->tile_count * (uint64_t)(ranks - 1);
    for (uint32_t t = 0; t < w->tile_count && rc == 0; t++) {
        int owner = c->owner_of(t, ranks), drawn = 0;
        if (owner != me) { /* draw, send the covered rectangle */
            if (!all[(size_t)me * w->tile_count + t])
                continue;
            if ((rc = draw_tile(c, t, mesh, own, err)) != 0)
                break; /* the caller ends the job; the owner waits for nothing more */
            start = wall_cpu_seconds();
            size_t n = pack_covered(own, w->tile_w, w->tile_h, packed);
            c->busy_seconds += wall_cpu_seconds() - start;
            wait = MPI_Wtime();
            wall_watch_stage("sending tile %u to rank %d at the composite", t, owner);
            MPI_Send(packed, (int)n, MPI_BYTE, owner, (int)t, MPI_COMM_WORLD);
            c->idle_seconds += MPI_Wtime() - wait;
            c->bytes_sent += n;
            continue;
        }
        rc = fill_background(c, t, result, column, err);
        for (int r = 0; r < ranks && rc == 0; r++) { /* in rank order: ties to the lower */
            if (!all[(size_t)r * w->tile_count + t])
                continue;
            if (r == me) { /* merged straight from the drawn tile, not packed first */
                if ((rc = draw_tile(c, t, mesh, own, err)) != 0)
                    break;
            } else {
                wait = MPI_Wtime();
                wall_watch_stage("waiting for tile %u from rank %d at the composite", t, r);
                MPI_Recv(packed, (int)(HEADER + bytes), MPI_BYTE, r, (int)t, MPI_COMM_WORLD,
                         MPI_STATUS_IGNORE);
                c->idle_seconds += MPI_Wtime() - wait;
            }
            start = wall_cpu_seconds();
            keep_nearest(result, w->tile_w, w->tile_h,
                         r == me ? whole(own, w->tile_w, w->tile_h) : unpacked(packed));
            c->busy_seconds += wall_cpu_seconds() - start;
            drawn = 1;
        }
        c->tiles_drawn += drawn;
        if (rc == 0)
            rc = done(t, result + pixels * sizeof(double), user, err);
    }
out:
    free(mine);
    free(all);
    free(result);
    free(own);
    free(packed);
    free(column);
    return rc;
}
