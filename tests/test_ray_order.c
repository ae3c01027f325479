/* SPDX-License-Identifier: BSD-3-Clause */
/* Progressive ray order: every pixel exactly once, centre first, evenly spread prefixes.
 * "test_ray_order --bench W H" times a full walk of a W x H image. */
#include <math.h>
#include <stdint.h>

#include "check.h"
#include "internal.h"
#include "ray_order.h"

/* Walks the whole order; checks bounds, repeats and the end. Returns the number of pixels. */
static uint64_t walk_once(uint32_t w, uint32_t h, uint64_t *hash)
{
    ip_ray_order order;
    REQUIRE(ip__ray_order_init(&order, w, h) == IP_OK);
    unsigned char *seen = calloc((size_t)w * h, 1);
    REQUIRE(seen);
    uint64_t n = 0, repeats = 0, outside = 0;
    uint32_t x, y, last_level = 0, level_went_back = 0;
    *hash = 1469598103934665603ull;
    while (ip__ray_order_next(&order, &x, &y)) {
        if (x >= w || y >= h) {
            outside++;
            continue;
        }
        repeats += seen[(size_t)y * w + x]++ != 0;
        if (n == 0)
            CHECK_MSG(x == w / 2 && y == h / 2, "%ux%u: first ray (%u, %u)", w, h, x, y);
        level_went_back += ip__ray_order_level(&order) < last_level;
        last_level = ip__ray_order_level(&order);
        *hash = (*hash ^ ((uint64_t)x << 32 | y)) * 1099511628211ull;
        n++;
    }
    CHECK_MSG(outside == 0 && repeats == 0, "%ux%u: %llu outside, %llu repeats", w, h,
              (unsigned long long)outside, (unsigned long long)repeats);
    CHECK_MSG(n == (uint64_t)w * h, "%ux%u: %llu pixels", w, h, (unsigned long long)n);
    CHECK_EQ(ip__ray_order_count(&order), (uint64_t)w * h);
    CHECK_EQ(ip__ray_order_emitted(&order), n);
    CHECK_EQ(level_went_back, 0);
    x = y = 12345;
    CHECK_EQ(ip__ray_order_next(&order, &x, &y), 0);
    CHECK_EQ(x, 12345);
    CHECK_EQ(y, 12345);
    free(seen);
    return n;
}

static void test_every_pixel_once(void)
{
    static const uint32_t sizes[][2] = {
        {1, 1},  {1, 7},    {7, 1},    {2, 2},     {3, 5},       {5, 3},       {16, 16},   {17, 13},
        {33, 2}, {1, 1000}, {1000, 1}, {640, 480}, {1600, 1200}, {1920, 1080}, {255, 257},
    };
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        uint64_t first, second;
        walk_once(sizes[i][0], sizes[i][1], &first);
        walk_once(sizes[i][0], sizes[i][1], &second);
        CHECK_MSG(first == second, "%ux%u: not deterministic", sizes[i][0], sizes[i][1]);
    }
}

/* The order as specified, the slow way: every cell of every level decoded from scratch, and a
 * bitmap of the pixels cast so far instead of the iterator's reasoning about coarser centres.
 * Levels from `local_from` on take the digits finest split first (Z-order). */
static void reference_order(uint32_t w, uint32_t h, uint32_t local_from, uint32_t (*out)[2])
{
    uint32_t kx = 0, ky = 0;
    while ((1ull << kx) < w)
        kx++;
    while ((1ull << ky) < h)
        ky++;
    unsigned char *seen = calloc((size_t)w * h, 1);
    REQUIRE(seen);
    static const uint32_t digit_x[4] = {0, 1, 1, 0}, digit_y[4] = {0, 1, 0, 1};
    size_t n = 0;
    for (uint32_t level = 0; level <= (kx > ky ? kx : ky); level++) {
        uint32_t nx = level < kx ? level : kx, ny = level < ky ? level : ky;
        uint32_t both = nx < ny ? nx : ny, splits = nx > ny ? nx : ny;
        int local = level >= local_from;
        /* every other local level, from the second, is walked from its end */
        uint64_t cells = 1ull << (nx + ny);
        int backward = local && ((level - local_from) & 1u);
        for (uint64_t position = 0; position < cells; position++) {
            uint64_t p = backward ? cells - 1 - position : position;
            uint32_t cx = 0, cy = 0;
            for (uint32_t s = 0; s < both; s++, p >>= 2) {
                cx |= digit_x[p & 3] << (local ? s : nx - 1 - s);
                cy |= digit_y[p & 3] << (local ? s : ny - 1 - s);
            }
            for (uint32_t s = both; s < splits; s++, p >>= 1) {
                if (nx > both)
                    cx |= (uint32_t)(p & 1) << (local ? s : nx - 1 - s);
                else
                    cy |= (uint32_t)(p & 1) << (local ? s : ny - 1 - s);
            }
            uint64_t x0 = (uint64_t)cx * w >> nx, x1 = (uint64_t)(cx + 1) * w >> nx;
            uint64_t y0 = (uint64_t)cy * h >> ny, y1 = (uint64_t)(cy + 1) * h >> ny;
            if (x0 == x1 || y0 == y1)
                continue;
            uint32_t px = (uint32_t)((x0 + x1) / 2), py = (uint32_t)((y0 + y1) / 2);
            if (seen[(size_t)py * w + px])
                continue;
            seen[(size_t)py * w + px] = 1;
            out[n][0] = px;
            out[n][1] = py;
            n++;
        }
    }
    REQUIRE(n == (size_t)w * h);
    free(seen);
}

/* Whether the iterator gives the reference order; with `range` > 0, walked in ranges of that
 * many positions, each from a seek, as the engine's threads walk it. */
static int same_as_reference(uint32_t w, uint32_t h, uint32_t local_from, uint64_t range)
{
    uint32_t(*expected)[2] = malloc((size_t)w * h * sizeof *expected);
    REQUIRE(expected);
    reference_order(w, h, local_from, expected);
    ip_ray_order order;
    REQUIRE(ip__ray_order_init(&order, w, h) == IP_OK);
    ip__ray_order_set_local_from(&order, local_from);
    uint64_t cells = ip__ray_order_cells(&order), start = 0, end = range ? range : UINT64_MAX;
    int same = 1;
    uint32_t x, y;
    for (size_t i = 0; i < (size_t)w * h && same; i++) {
        while (!ip__ray_order_next_before(&order, end, &x, &y) && start < cells) {
            start = end < cells ? end : cells;
            end = start + range;
            ip__ray_order_seek(&order, start);
        }
        same = x == expected[i][0] && y == expected[i][1];
    }
    free(expected);
    ip__ray_order_seek(&order, cells);
    return same && !ip__ray_order_next(&order, &x, &y);
}

/* Ranges walked last first, each from a seek (as the engine's leftover ranges are): every
 * range gives the pixels it gives in a walk from the start. */
static void test_ranges_backwards(uint32_t w, uint32_t h, uint32_t local_from, uint64_t range)
{
    ip_ray_order order;
    REQUIRE(ip__ray_order_init(&order, w, h) == IP_OK);
    ip__ray_order_set_local_from(&order, local_from);
    uint64_t cells = ip__ray_order_cells(&order), n = (uint64_t)w * h;
    uint64_t ranges = (cells + range - 1) / range;
    uint32_t(*forward)[2] = malloc(n * sizeof *forward);
    uint64_t *first = malloc((ranges + 1) * sizeof *first); /* first pixel of each range */
    REQUIRE(forward && first);
    uint64_t i = 0;
    for (uint64_t r = 0; r < ranges; r++) {
        first[r] = i;
        while (ip__ray_order_next_before(&order, (r + 1) * range, &forward[i][0], &forward[i][1]))
            i++;
    }
    first[ranges] = i;
    REQUIRE(i == n);
    uint64_t differ = 0;
    for (uint64_t r = ranges; r-- > 0;) {
        ip__ray_order_seek(&order, r * range);
        uint32_t x, y;
        for (uint64_t j = first[r]; j < first[r + 1]; j++)
            differ += !ip__ray_order_next_before(&order, (r + 1) * range, &x, &y) ||
                      x != forward[j][0] || y != forward[j][1];
        differ += ip__ray_order_next_before(&order, (r + 1) * range, &x, &y);
    }
    CHECK_MSG(differ == 0, "%ux%u, ranges of %llu walked backwards: %llu differ", w, h,
              (unsigned long long)range, (unsigned long long)differ);
    free(forward);
    free(first);
}

static void test_matches_reference(void)
{
    int mismatches = 0;
    for (uint32_t w = 1; w <= 40; w++)
        for (uint32_t h = 1; h <= 40; h++) {
            if (!same_as_reference(w, h, UINT32_MAX, 0))
                fprintf(stderr, "%ux%u differs from the reference order\n", w, h), mismatches++;
            if (!same_as_reference(w, h, 2, 7))
                fprintf(stderr, "%ux%u, local from 2, in ranges of 7: differs\n", w, h),
                    mismatches++;
        }
    CHECK_EQ(mismatches, 0);
    static const uint32_t sizes[][2] = {
        {640, 480}, {255, 257}, {1000, 3}, {129, 1025}, {1600, 1200}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        uint32_t w = sizes[i][0], h = sizes[i][1];
        CHECK_MSG(same_as_reference(w, h, UINT32_MAX, 0), "%ux%u", w, h);
        /* the engine's set-up: the last 3 levels local, ranges of a few hundred positions */
        ip_ray_order order;
        REQUIRE(ip__ray_order_init(&order, w, h) == IP_OK);
        uint32_t last = ip__ray_order_last_level(&order);
        CHECK_MSG(same_as_reference(w, h, last > 3 ? last - 3 : 0, 333), "%ux%u local", w, h);
        test_ranges_backwards(w, h, last > 3 ? last - 3 : 0, 1000);
    }
}

static void test_first_rays(void)
{
    /* 16 x 16: the centre, then the 4 quadrant centres in Bayer order, then the 16 sub-quadrant
     * centres starting with the lattice of every other one. */
    static const uint32_t expected[][2] = {{8, 8}, {4, 4},   {12, 12}, {12, 4}, {4, 12},
                                           {2, 2}, {10, 10}, {10, 2},  {2, 10}, {6, 6}};
    ip_ray_order order;
    REQUIRE(ip__ray_order_init(&order, 16, 16) == IP_OK);
    for (size_t i = 0; i < sizeof expected / sizeof expected[0]; i++) {
        uint32_t x = 0, y = 0;
        CHECK_EQ(ip__ray_order_next(&order, &x, &y), 1);
        CHECK_MSG(x == expected[i][0] && y == expected[i][1], "ray %zu is (%u, %u)", i, x, y);
        CHECK_EQ(ip__ray_order_level(&order), i == 0 ? 0u : i < 5 ? 1u : 2u);
    }
    /* Reset replays the same order. */
    ip__ray_order_reset(&order);
    CHECK_EQ(ip__ray_order_emitted(&order), 0);
    uint32_t x = 0, y = 0;
    CHECK_EQ(ip__ray_order_next(&order, &x, &y), 1);
    CHECK_EQ(x, 8);
    CHECK_EQ(y, 8);
    /* A single row: the centre, then the quarter points. */
    REQUIRE(ip__ray_order_init(&order, 8, 1) == IP_OK);
    static const uint32_t row[8] = {4, 2, 6, 1, 5, 3, 7, 0};
    for (int i = 0; i < 8; i++) {
        CHECK_EQ(ip__ray_order_next(&order, &x, &y), 1);
        CHECK_EQ(y, 0);
        CHECK_MSG(x == row[i], "8x1 ray %d is %u", i, x);
    }
}

static void test_bad_arguments(void)
{
    ip_ray_order order;
    CHECK_EQ(ip__ray_order_init(NULL, 4, 4), IP_ERR_ARGUMENT);
    CHECK_EQ(ip__ray_order_init(&order, 0, 4), IP_ERR_ARGUMENT);
    CHECK_EQ(ip__ray_order_init(&order, 4, 0), IP_ERR_ARGUMENT);
    CHECK_EQ(ip__ray_order_init(&order, IP_RAY_ORDER_MAX_SIDE + 1, 4), IP_ERR_ARGUMENT);
    CHECK_EQ(ip__ray_order_init(&order, IP_RAY_ORDER_MAX_SIDE, 1), IP_OK);
    uint32_t x, y;
    CHECK_EQ(ip__ray_order_next(&order, &x, &y), 1);
    CHECK_EQ(x, IP_RAY_ORDER_MAX_SIDE / 2);
    CHECK_EQ(y, 0);
    CHECK_EQ(ip__ray_order_count(&order), IP_RAY_ORDER_MAX_SIDE);
}

/* Exact squared Euclidean distance transform along one line: the lower envelope of the
 * parabolas (q - p)^2 + f[p]; v holds the envelope's parabolas, z the boundaries between them. */
static void distance_1d(const double *f, double *d, int n, int *v, double *z)
{
    int k = 0;
    v[0] = 0;
    z[0] = -HUGE_VAL;
    z[1] = HUGE_VAL;
    for (int q = 1; q < n; q++) {
        double s;
        for (;;) {
            int p = v[k];
            s = ((f[q] + (double)q * q) - (f[p] + (double)p * p)) / (2.0 * (q - p));
            if (s > z[k])
                break;
            k--;
        }
        k++;
        v[k] = q;
        z[k] = s;
        z[k + 1] = HUGE_VAL;
    }
    k = 0;
    for (int q = 0; q < n; q++) {
        while (z[k + 1] < q)
            k++;
        double dq = q - v[k];
        d[q] = dq * dq + f[v[k]];
    }
}

/* Largest distance in pixels from any pixel to a cast one (cast[i] != 0). */
static double max_distance(const unsigned char *cast, uint32_t w, uint32_t h)
{
    uint32_t n = w > h ? w : h;
    double *grid = malloc((size_t)w * h * sizeof *grid);
    double *f = malloc(n * sizeof *f), *d = malloc(n * sizeof *d), *z = malloc((n + 1) * sizeof *z);
    int *v = malloc(n * sizeof *v);
    REQUIRE(grid && f && d && z && v);
    /* Beyond any real squared distance, yet small enough that sums stay exact. */
    const double far = 4.0 * ((double)w * w + (double)h * h) + 1.0;
    for (uint32_t x = 0; x < w; x++) {
        for (uint32_t y = 0; y < h; y++)
            f[y] = cast[(size_t)y * w + x] ? 0.0 : far;
        distance_1d(f, d, (int)h, v, z);
        for (uint32_t y = 0; y < h; y++)
            grid[(size_t)y * w + x] = d[y];
    }
    double worst = 0.0;
    for (uint32_t y = 0; y < h; y++) {
        distance_1d(&grid[(size_t)y * w], d, (int)w, v, z);
        for (uint32_t x = 0; x < w; x++)
            if (d[x] > worst)
                worst = d[x];
    }
    free(grid);
    free(f);
    free(d);
    free(z);
    free(v);
    return sqrt(worst);
}

/* Largest chessboard distance max(|dx|, |dy|) from any pixel to a cast one: two raster passes
 * over the 8-neighbourhood, which are exact for this metric. */
static uint32_t max_chessboard_distance(const unsigned char *cast, uint32_t w, uint32_t h)
{
    uint32_t *d = malloc((size_t)w * h * sizeof *d);
    REQUIRE(d);
    const uint32_t far = w + h;
    for (size_t i = 0; i < (size_t)w * h; i++)
        d[i] = cast[i] ? 0 : far;
    for (int pass = 0; pass < 2; pass++) {
        for (uint32_t r = 0; r < h; r++) {
            uint32_t y = pass ? h - 1 - r : r;
            int dy = pass ? 1 : -1;
            for (uint32_t c = 0; c < w; c++) {
                uint32_t x = pass ? w - 1 - c : c;
                uint32_t best = d[(size_t)y * w + x];
                /* The neighbours already visited in this pass. */
                static const int dx_of[4] = {-1, 0, 1, -1};
                for (int k = 0; k < 4; k++) {
                    int nx = (int)x + (pass ? -dx_of[k] : dx_of[k]);
                    int ny = k == 3 ? (int)y : (int)y + dy;
                    if (nx < 0 || ny < 0 || nx >= (int)w || ny >= (int)h)
                        continue;
                    uint32_t via = d[(size_t)ny * w + (uint32_t)nx] + 1;
                    if (via < best)
                        best = via;
                }
                d[(size_t)y * w + x] = best;
            }
        }
    }
    uint32_t worst = 0;
    for (size_t i = 0; i < (size_t)w * h; i++)
        if (d[i] > worst)
            worst = d[i];
    free(d);
    return worst;
}

/* Brute force, to check the distance transforms themselves on small images. */
static double max_distance_brute(const unsigned char *cast, uint32_t w, uint32_t h, int chessboard)
{
    double worst = 0.0;
    for (uint32_t py = 0; py < h; py++)
        for (uint32_t px = 0; px < w; px++) {
            double best = HUGE_VAL;
            for (uint32_t y = 0; y < h; y++)
                for (uint32_t x = 0; x < w; x++)
                    if (cast[(size_t)y * w + x]) {
                        double dx = fabs((double)x - px), dy = fabs((double)y - py);
                        double dist = chessboard ? (dx > dy ? dx : dy) : sqrt(dx * dx + dy * dy);
                        if (dist < best)
                            best = dist;
                    }
            if (best > worst)
                worst = best;
        }
    return worst;
}

/* ceil(side / 2^k): the largest cell of level k along a side, at least 1. */
static uint32_t cell_size(uint32_t side, uint32_t k)
{
    if (k >= 32)
        return 1;
    uint32_t size = (uint32_t)(((uint64_t)side + (1ull << k) - 1) >> k);
    return size < 1 ? 1 : size;
}

/* The asserted bounds, with S = max(W, H):
 *  - after the first 4^k rays, the chessboard distance max(|dx|, |dy|) from every pixel to a cast
 *    ray is <= ceil(S / 2^k), which is W / 2^k for square power-of-two images, and the
 *    Euclidean distance is <= sqrt(2) times that. (Levels 0..k-1 are complete by then; the
 *    Euclidean W / 2^k itself is out of reach for any order that starts with the centre and the
 *    quadrant centres: after 4 rays one quadrant is still empty and its far corner is
 *    sqrt((W/2)^2 + (W/2 - 1)^2) from the centre.)
 *  - once level k is complete, each pixel is within floor(c / 2) of its cell's centre along each
 *    axis, c being the largest level-k cell along that axis: the Euclidean distance is at most
 *    sqrt(floor(cw / 2)^2 + floor(ch / 2)^2). */
static void test_spread(uint32_t w, uint32_t h)
{
    ip_ray_order order;
    REQUIRE(ip__ray_order_init(&order, w, h) == IP_OK);
    unsigned char *cast = calloc((size_t)w * h, 1);
    REQUIRE(cast);
    uint32_t side = w > h ? w : h;
    uint64_t emitted = 0, next_checkpoint = 1;
    uint32_t x, y, k = 0, level = 0;
    printf("%ux%u, after 4^k rays (chessboard/euclidean):", w, h);
    int more = ip__ray_order_next(&order, &x, &y);
    while (more) {
        cast[(size_t)y * w + x] = 1;
        emitted++;
        if (emitted == next_checkpoint) {
            uint32_t chess = max_chessboard_distance(cast, w, h);
            double euclid = max_distance(cast, w, h), bound = cell_size(side, k);
            printf(" %u/%.2f", chess, euclid);
            CHECK_MSG(chess <= bound, "%ux%u after 4^%u rays: chessboard %u > %.0f", w, h, k, chess,
                      bound);
            CHECK_MSG(euclid <= sqrt(2.0) * bound + 1e-9, "%ux%u after 4^%u rays: %.3f > %.3f", w,
                      h, k, euclid, sqrt(2.0) * bound);
            next_checkpoint *= 4;
            k++;
        }
        more = ip__ray_order_next(&order, &x, &y);
        if (!more || ip__ray_order_level(&order) != level) {
            uint32_t cw = cell_size(w, level), ch = cell_size(h, level);
            double bound = sqrt((double)(cw / 2) * (cw / 2) + (double)(ch / 2) * (ch / 2));
            double worst = max_distance(cast, w, h);
            CHECK_MSG(worst <= bound + 1e-9, "%ux%u level %u: %.3f > %.3f", w, h, level, worst,
                      bound);
            level = ip__ray_order_level(&order);
        }
    }
    printf("\n");
    free(cast);
}

static void test_distance_transform(void)
{
    uint64_t state = 3;
    for (int trial = 0; trial < 20; trial++) {
        uint32_t w = 5 + (uint32_t)trial, h = 23 - (uint32_t)trial / 2;
        unsigned char *cast = calloc((size_t)w * h, 1);
        REQUIRE(cast);
        for (int i = 0; i < 1 + trial; i++) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            cast[(state >> 33) % ((uint64_t)w * h)] = 1;
        }
        CHECK_NEAR(max_distance(cast, w, h), max_distance_brute(cast, w, h, 0), 1e-9);
        CHECK_EQ(max_chessboard_distance(cast, w, h), (uint32_t)max_distance_brute(cast, w, h, 1));
        free(cast);
    }
}

/* Local levels: each level holds the same pixels as in Bayer order, the levels before the
 * first local one come in the very same sequence, every pixel still comes once, and within a
 * local level consecutive rays are near each other (a mean chessboard step under 1/16 of
 * Bayer order's, which jumps across the screen). */
/* The chessboard distance between two pixels (level, x, y). */
static uint32_t chessboard(const uint32_t a[3], const uint32_t b[3])
{
    uint32_t dx = a[1] > b[1] ? a[1] - b[1] : b[1] - a[1],
             dy = a[2] > b[2] ? a[2] - b[2] : b[2] - a[2];
    return dx > dy ? dx : dy;
}

static void test_local_levels(uint32_t w, uint32_t h, uint32_t local_from)
{
    ip_ray_order bayer, local;
    REQUIRE(ip__ray_order_init(&bayer, w, h) == IP_OK && ip__ray_order_init(&local, w, h) == IP_OK);
    ip__ray_order_set_local_from(&local, local_from);
    uint64_t n = (uint64_t)w * h;
    uint32_t(*a)[3] = malloc(n * sizeof *a), (*b)[3] = malloc(n * sizeof *b);
    REQUIRE(a && b);
    for (int pass = 0; pass < 2; pass++) { /* the second pass after a reset: the same again */
        uint64_t i = 0;
        uint32_t x, y;
        while (ip__ray_order_next(&bayer, &x, &y))
            a[i][0] = ip__ray_order_level(&bayer), a[i][1] = x, a[i++][2] = y;
        REQUIRE(i == n);
        i = 0;
        while (ip__ray_order_next(&local, &x, &y) && i < n)
            b[i][0] = ip__ray_order_level(&local), b[i][1] = x, b[i++][2] = y;
        CHECK_MSG(i == n, "%ux%u local from %u: %llu pixels", w, h, local_from,
                  (unsigned long long)i);
        ip__ray_order_reset(&bayer);
        ip__ray_order_reset(&local);
    }
    /* level by level: the same pixels (as sets), in the same order before local_from */
    unsigned char *in_level = calloc(n, 1);
    REQUIRE(in_level);
    uint64_t start = 0, differ = 0, order_differs = 0, jumps_far = 0, boundaries = 0;
    double steps = 0, bayer_steps = 0;
    uint64_t step_count = 0;
    while (start < n) {
        uint64_t end = start;
        while (end < n && a[end][0] == a[start][0])
            end++;
        for (uint64_t i = start; i < end; i++)
            in_level[(size_t)a[i][2] * w + a[i][1]] = 1;
        for (uint64_t i = start; i < end; i++) {
            differ += b[i][0] != a[start][0] || !in_level[(size_t)b[i][2] * w + b[i][1]];
            if (a[start][0] < local_from)
                order_differs += b[i][1] != a[i][1] || b[i][2] != a[i][2];
            else if (i > start) {
                uint32_t dx = b[i][1] > b[i - 1][1] ? b[i][1] - b[i - 1][1] : b[i - 1][1] - b[i][1];
                uint32_t dy = b[i][2] > b[i - 1][2] ? b[i][2] - b[i - 1][2] : b[i - 1][2] - b[i][2];
                uint32_t ex = a[i][1] > a[i - 1][1] ? a[i][1] - a[i - 1][1] : a[i - 1][1] - a[i][1];
                uint32_t ey = a[i][2] > a[i - 1][2] ? a[i][2] - a[i - 1][2] : a[i - 1][2] - a[i][2];
                steps += dx > dy ? dx : dy;
                bayer_steps += ex > ey ? ex : ey;
                step_count++;
            }
        }
        for (uint64_t i = start; i < end; i++)
            in_level[(size_t)a[i][2] * w + a[i][1]] = 0;
        /* a local level after the first starts where the one before ended (walked backward
         * every other level), within a few of the last level's cells, not across the screen;
         * skipped cells (empty, or cast before) can move a sparse level's first ray away */
        if (start > 0 && a[start][0] > local_from && a[start][0] > a[start - 1][0]) {
            uint32_t cell = (w > h ? w : h) >> a[start - 1][0];
            boundaries++;
            jumps_far += chessboard(b[start - 1], b[start]) > 4 * cell + 4;
        }
        start = end;
    }
    CHECK_MSG(differ == 0, "%ux%u local from %u: %llu rays in another level", w, h, local_from,
              (unsigned long long)differ);
    CHECK_MSG(order_differs == 0, "%ux%u local from %u: coarse levels reordered", w, h, local_from);
    CHECK_MSG(jumps_far * 4 <= boundaries,
              "%ux%u local from %u: %llu of %llu local levels start far from the last", w, h,
              local_from, (unsigned long long)jumps_far, (unsigned long long)boundaries);
    if (step_count > 0) {
        double mean = steps / (double)step_count, bayer_mean = bayer_steps / (double)step_count;
        printf("%ux%u local from level %u: mean step %.2f pixels (Bayer order: %.2f)\n", w, h,
               local_from, mean, bayer_mean);
        CHECK_MSG(mean * 16 < bayer_mean, "%ux%u: mean step %.2f, Bayer %.2f", w, h, mean,
                  bayer_mean);
    }
    free(in_level);
    free(a);
    free(b);
}

static int bench(uint32_t w, uint32_t h)
{
    ip_ray_order order;
    if (ip__ray_order_init(&order, w, h) != IP_OK)
        return 1;
    uint64_t sum = 0, n = 0;
    uint32_t x, y;
    double start = ip_now_seconds();
    while (ip__ray_order_next(&order, &x, &y)) {
        sum += x ^ y;
        n++;
    }
    double seconds = ip_now_seconds() - start;
    printf("%ux%u: %llu pixels in %.4f s: %.1f M pixels/s (checksum %llu)\n", w, h,
           (unsigned long long)n, seconds, n / seconds / 1e6, (unsigned long long)sum);
    return 0;
}

/* Ranges of positions walked by separate iterators, each from a seek, give exactly the pixels
 * of one uninterrupted walk in the same order, for ranges of any length and local levels. */
static void test_ranges(uint32_t w, uint32_t h, uint32_t local_from, uint64_t range)
{
    ip_ray_order whole, part;
    REQUIRE(ip__ray_order_init(&whole, w, h) == IP_OK);
    REQUIRE(ip__ray_order_init(&part, w, h) == IP_OK);
    ip__ray_order_set_local_from(&whole, local_from);
    ip__ray_order_set_local_from(&part, local_from);
    uint64_t cells = ip__ray_order_cells(&whole), n = 0, differ = 0;
    CHECK_GE(cells, (uint64_t)w * h);
    for (uint64_t start = 0; start < cells; start += range) {
        uint64_t end = cells - start < range ? cells : start + range;
        ip__ray_order_seek(&part, start);
        CHECK_EQ(ip__ray_order_position(&part), start);
        uint32_t x, y, ex, ey;
        while (ip__ray_order_next_before(&part, end, &x, &y)) {
            n++;
            differ += !ip__ray_order_next(&whole, &ex, &ey) || ex != x || ey != y;
        }
        differ += ip__ray_order_position(&part) != end;
    }
    uint32_t x, y;
    CHECK_MSG(differ == 0 && n == (uint64_t)w * h && !ip__ray_order_next(&whole, &x, &y),
              "%ux%u, ranges of %llu: %llu differ, %llu pixels", w, h, (unsigned long long)range,
              (unsigned long long)differ, (unsigned long long)n);
}

static int pixel_less(const void *a, const void *b)
{
    const uint32_t *p = a, *q = b;
    return p[1] != q[1] ? (p[1] > q[1]) - (p[1] < q[1]) : (p[0] > q[0]) - (p[0] < q[0]);
}

/* Blocks (ip__ray_order_block(), ip__ray_order_skip_block()): a walk that moves past every
 * block of 4^k cells it stands at, in ranges from seeks, returns the pixels of next() with
 * each block's pixels in place of the same number of next()'s, as the same set; the pixel
 * count and emitted() add up, and blocks are found only in local levels. */
static void test_blocks(uint32_t w, uint32_t h, uint32_t local_from, uint32_t k, uint64_t range)
{
    uint64_t n = (uint64_t)w * h;
    uint32_t(*expected)[2] = malloc(n * sizeof *expected), (*got)[2] = malloc(n * sizeof *got);
    REQUIRE(expected && got);
    ip_ray_order order;
    REQUIRE(ip__ray_order_init(&order, w, h) == IP_OK);
    ip__ray_order_set_local_from(&order, local_from);
    for (uint64_t i = 0; i < n; i++)
        REQUIRE(ip__ray_order_next(&order, &expected[i][0], &expected[i][1]));
    ip__ray_order_reset(&order);
    uint64_t cells = ip__ray_order_cells(&order), i = 0, blocks = 0, wrong = 0, early = 0;
    uint32_t xs[256], ys[256];
    for (uint64_t start = 0; start < cells; start += range) {
        ip__ray_order_seek(&order, start);
        uint64_t end = start + range;
        for (;;) {
            unsigned count;
            uint64_t at = ip__ray_order_position(&order);
            if (at + ((uint64_t)1 << 2 * k) <= end &&
                ip__ray_order_block(&order, k, xs, ys, &count)) {
                REQUIRE(i + count <= n);
                early += ip__ray_order_level(&order) < local_from;
                uint64_t before = ip__ray_order_emitted(&order);
                ip__ray_order_skip_block(&order, k, count);
                wrong += ip__ray_order_emitted(&order) != before + count ||
                         ip__ray_order_position(&order) != at + ((uint64_t)1 << 2 * k);
                for (unsigned j = 0; j < count; j++)
                    got[i + j][0] = xs[j], got[i + j][1] = ys[j];
                qsort(got + i, count, sizeof *got, pixel_less);
                qsort(expected + i, count, sizeof *expected, pixel_less);
                blocks++;
                i += count;
            } else if (ip__ray_order_next_before(&order, end, &got[i][0], &got[i][1])) {
                REQUIRE(i < n);
                i++;
            } else
                break;
        }
    }
    for (uint64_t j = 0; j < i && j < n; j++)
        wrong += got[j][0] != expected[j][0] || got[j][1] != expected[j][1];
    CHECK_MSG(i == n && wrong == 0 && early == 0 && blocks > 0,
              "%ux%u, blocks of 4^%u, ranges of %llu: %llu pixels of %llu, %llu wrong, %llu "
              "blocks (%llu before the local levels)",
              w, h, k, (unsigned long long)range, (unsigned long long)i, (unsigned long long)n,
              (unsigned long long)wrong, (unsigned long long)blocks, (unsigned long long)early);
    free(expected);
    free(got);
}

/* ip__ray_order_level_position(): seeking to it puts the iterator at its level's first cell,
 * one before it in the level before, and past the last level it is the number of cells. */
static void test_level_positions(uint32_t w, uint32_t h)
{
    ip_ray_order order;
    REQUIRE(ip__ray_order_init(&order, w, h) == IP_OK);
    uint32_t last = ip__ray_order_last_level(&order), wrong = 0;
    for (uint32_t k = 1; k <= last; k++) {
        uint64_t at = ip__ray_order_level_position(&order, k);
        ip__ray_order_seek(&order, at);
        wrong += ip__ray_order_level(&order) != k || ip__ray_order_position(&order) != at;
        ip__ray_order_seek(&order, at - 1);
        wrong += ip__ray_order_level(&order) != k - 1;
    }
    CHECK_MSG(wrong == 0 && ip__ray_order_level_position(&order, 0) == 0 &&
                  ip__ray_order_level_position(&order, last + 1) == ip__ray_order_cells(&order),
              "%ux%u: %u level positions wrong", w, h, wrong);
}

static void test_spreads(void)
{
    test_spread(64, 64);
    test_spread(256, 256);
    test_spread(256, 128);
    test_spread(17, 13);
    test_spread(640, 480);
    test_spread(1, 100);
}

static void test_local_levels_all(void)
{
    test_local_levels(1600, 1200, 8);
    test_local_levels(640, 480, 0);
    test_local_levels(255, 257, 5);
    test_local_levels(1000, 1, 3);
    test_local_levels(17, 13, 40); /* past the last level: Bayer order throughout */
}

static void test_ranges_all(void)
{
    test_ranges(1600, 1200, 8, 64);
    test_ranges(1600, 1200, UINT32_MAX, 1000);
    test_ranges(17, 13, 2, 1);
    test_ranges(1000, 1, 3, 7);
    test_ranges(1, 1, 0, 1);
    test_ranges(255, 257, 5, 3);
}

static void test_blocks_all(void)
{
    test_blocks(1600, 1200, 8, 3, 1000);
    test_blocks(255, 257, 5, 2, 333);
    test_blocks(97, 61, 4, 1, 16);
    test_blocks(640, 480, 0, 4, 1u << 20);
    test_blocks(1000, 3, 2, 1, 64); /* the shorter axis stops splitting: few blocks */
}

static void test_level_positions_all(void)
{
    test_level_positions(1600, 1200);
    test_level_positions(1000, 3);
    test_level_positions(1, 1);
}

static const test_case cases[] = {
    TEST_CASE(test_every_pixel_once),
    TEST_CASE(test_matches_reference),
    TEST_CASE(test_first_rays),
    TEST_CASE(test_bad_arguments),
    TEST_CASE(test_distance_transform),
    {"test_spread", test_spreads},
    {"test_local_levels", test_local_levels_all},
    {"test_ranges", test_ranges_all},
    {"test_blocks", test_blocks_all},
    {"test_level_positions", test_level_positions_all},
};

int main(int argc, char **argv)
{
    if (argc > 3 && strcmp(argv[1], "--bench") == 0)
        return bench((uint32_t)atoi(argv[2]), (uint32_t)atoi(argv[3]));
    return RUN_CASES(argc, argv, cases, "test_ray_order");
}
