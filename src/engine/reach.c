/* Screen tiles that the bricks holding the isovalue may show in. */
#include <math.h>
#include <string.h>

#include "reach.h"
#include "sampler.h"

void ip__reach_box(const ip_camera_basis *basis, const ip_camera *camera, const double lo[3],
                   const double hi[3], unsigned shift, uint32_t tiles_x, uint32_t tiles_y,
                   unsigned char *reached)
{
    double min_x = INFINITY, max_x = -INFINITY, min_y = INFINITY, max_y = -INFINITY;
    for (int c = 0; c < 8; c++) {
        double p[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        double x, y, depth;
        if (!ip_camera_project(basis, camera, p, &x, &y, &depth)) {
            min_x = min_y = -INFINITY;
            max_x = max_y = INFINITY;
            break;
        }
        min_x = x < min_x ? x : min_x;
        max_x = x > max_x ? x : max_x;
        min_y = y < min_y ? y : min_y;
        max_y = y > max_y ? y : max_y;
    }
    /* pixel x's centre x + 0.5 within [min - 1, max + 1]: x in [min - 1.5, max + 0.5] */
    double side = (double)(1u << shift);
    double tx0 = fmax(floor((min_x - 1.5) / side), 0),
           tx1 = fmin(floor((max_x + 0.5) / side), tiles_x - 1.0);
    double ty0 = fmax(floor((min_y - 1.5) / side), 0),
           ty1 = fmin(floor((max_y + 0.5) / side), tiles_y - 1.0);
    if (!(tx0 <= tx1)) /* left or right of the image */
        return;
    for (double ty = ty0; ty <= ty1; ty++)
        memset(reached + (size_t)ty * tiles_x + (size_t)tx0, 1, (size_t)(tx1 - tx0) + 1);
}

void ip__reach_tiles(const ip_store *store, float iso, uint32_t levels,
                     const ip_camera_basis *basis, const ip_camera *camera, unsigned shift,
                     uint32_t tiles_x, uint32_t tiles_y, unsigned char *reached)
{
    const ip_layout *l = ip_store_layout(store);
    memset(reached, 0, (size_t)tiles_x * tiles_y);
    for (uint32_t k = 0; k < levels; k++) {
        const ip_level_layout *lv = &l->levels[k];
        uint32_t b[3];
        for (b[2] = 0; b[2] < lv->bricks[2]; b[2]++)
            for (b[1] = 0; b[1] < lv->bricks[1]; b[1]++)
                for (b[0] = 0; b[0] < lv->bricks[0]; b[0]++) {
                    float range[2];
                    ip_store_brick_range(store, ip_brick_global_index(l, k, b), range);
                    if (!ip__range_active(range[0], range[1], iso))
                        continue;
                    uint32_t origin[3], extent[3];
                    ip_brick_extent(l, k, b, origin, extent);
                    double lo[3], hi[3];
                    for (int a = 0; a < 3; a++) {
                        double scale = l->spacing[a] * (double)(1u << k);
                        lo[a] = origin[a] * scale;
                        hi[a] = (origin[a] + extent[a] - 1.0) * scale;
                    }
                    ip__reach_box(basis, camera, lo, hi, shift, tiles_x, tiles_y, reached);
                }
    }
}
