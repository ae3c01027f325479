/* Compositing the wall: per display tile, the processes whose triangles reach it draw them
 * (depth and colour) and send the tile to its owner, which keeps the nearest surface of each
 * pixel (direct send; ties go to the lower rank, so the result does not depend on timing). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "composite.h"

#include <time.h>

double wall_cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One rank's tile as sent: inverse depths (doubles), then the colours (4 bytes a pixel). */
static size_t tile_bytes(size_t pixels)
{
    return pixels * (sizeof(double) + 4);
}

/* Keeps, per pixel, the nearer of `into` and the tile `from` (strictly nearer: on equal depth
 * the earlier contribution stays). */
static void keep_nearest(uint8_t *into, const uint8_t *from, size_t pixels)
{
    double *depth = (double *)into;
    const double *other = (const double *)from;
    uint8_t *rgba = into + pixels * sizeof(double);
    const uint8_t *other_rgba = from + pixels * sizeof(double);
    for (size_t i = 0; i < pixels; i++)
        if (other[i] > depth[i]) {
            depth[i] = other[i];
            memcpy(rgba + 4 * i, other_rgba + 4 * i, 4);
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
    ip_status st = ip_raster_mesh_part(mesh, &w->camera, c->shading, w->lo, w->hi, col * w->tile_w,
                                       row * w->tile_h, w->tile_w, w->tile_h, (double *)buf,
                                       buf + pixels * sizeof(double), err);
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
    uint8_t *result = malloc(bytes), *incoming = malloc(bytes), *own = malloc(bytes);
    int rc = mine && all && result && incoming && own ? 0 : -1;
    if (rc != 0) {
        err->code = IP_ERR_NOMEM;
        snprintf(err->message, sizeof err->message, "out of memory for a %ux%u tile", w->tile_w,
                 w->tile_h);
    }
    double start = wall_cpu_seconds();
    if (rc == 0)
        wall_touched_tiles(w, mesh, mine);
    c->busy_seconds += wall_cpu_seconds() - start;
    /* every rank learns who draws what (one byte per tile and rank) */
    double wait = MPI_Wtime();
    MPI_Allgather(mine ? mine : result, (int)w->tile_count, MPI_BYTE, all, (int)w->tile_count,
                  MPI_BYTE, MPI_COMM_WORLD);
    c->idle_seconds += MPI_Wtime() - wait;
    c->bytes_sent += (uint64_t)w->tile_count * (uint64_t)(ranks - 1);
    int failed = rc;
    MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (failed != 0) {
        rc = -1;
        goto out;
    }
    for (uint32_t t = 0; t < w->tile_count && rc == 0; t++) {
        int owner = c->owner_of(t, ranks), drawn = 0;
        if (owner != me) {
            if (!all[(size_t)me * w->tile_count + t])
                continue;
            rc = draw_tile(c, t, mesh, own, err);
            wait = MPI_Wtime();
            MPI_Send(own, (int)bytes, MPI_BYTE, owner, (int)t, MPI_COMM_WORLD);
            c->idle_seconds += MPI_Wtime() - wait;
            c->bytes_sent += bytes;
            continue;
        }
        for (int r = 0; r < ranks && rc == 0; r++) {
            if (!all[(size_t)r * w->tile_count + t])
                continue;
            uint8_t *from = drawn ? incoming : result;
            if (r == me) {
                rc = draw_tile(c, t, mesh, from, err);
            } else {
                wait = MPI_Wtime();
                MPI_Recv(from, (int)bytes, MPI_BYTE, r, (int)t, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                c->idle_seconds += MPI_Wtime() - wait;
            }
            start = wall_cpu_seconds();
            if (drawn)
                keep_nearest(result, incoming, pixels);
            c->busy_seconds += wall_cpu_seconds() - start;
            drawn = 1;
        }
        if (rc == 0 && !drawn) { /* no rank's triangles reach it: the background */
            ip_mesh empty;
            ip_mesh_init(&empty);
            rc = draw_tile(c, t, &empty, result, err);
        }
        c->tiles_drawn += drawn;
        if (rc == 0)
            rc = done(t, result + pixels * sizeof(double), user, err);
    }
out:
    free(mine);
    free(all);
    free(result);
    free(incoming);
    free(own);
    return rc;
}
