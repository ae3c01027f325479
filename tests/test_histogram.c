/* SPDX-License-Identifier: BSD-3-Clause */
/* The histogram against a direct count of the raw samples: at every level (the pyramid takes
 * every 2^k-th sample), for integer and float types, with constant bricks; the active
 * sub-blocks against a brute-force count over the summaries; the default level; bad
 * arguments. */
#include <math.h>

#include "check.h"
#include "isoprop/histogram.h"
#include "isoprop/store.h"
#include "volumes.h"

/* The raw file's samples as doubles (host order is little-endian on every supported host). */
static double *read_raw(const char *path, const ip_gen_params *p, size_t *count)
{
    *count = (size_t)p->dims[0] * p->dims[1] * p->dims[2];
    size_t size = ip_type_size(p->type);
    unsigned char *bytes = malloc(*count * size);
    double *v = malloc(*count * sizeof *v);
    FILE *f = fopen(path, "rb");
    REQUIRE(bytes && v && f && fread(bytes, size, *count, f) == *count);
    fclose(f);
    for (size_t i = 0; i < *count; i++)
        v[i] = ip_sample_get(bytes, p->type, i);
    free(bytes);
    return v;
}

/* The bin the histogram's own edges give `v`: the last bin whose lo <= v. */
static uint32_t expected_bin(const ip_histogram *h, double v)
{
    uint32_t b = 0;
    while (b + 1 < h->bin_count && h->bins[b + 1].lo <= v)
        b++;
    return b;
}

/* Counts level `k`'s samples of the raw volume directly and compares them bin by bin. */
static void check_level(const ip_store *s, const double *raw, const ip_gen_params *p, uint32_t k,
                        uint32_t bins)
{
    ip_histogram *h = NULL;
    ip_error err;
    REQUIRE(ip_histogram_compute(s, k, bins, &h, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    const uint32_t *d = l->levels[k].dims;
    CHECK_EQ(h->level, k);
    CHECK_EQ(h->samples, (uint64_t)d[0] * d[1] * d[2]);
    uint64_t *want = calloc(h->bin_count, sizeof *want);
    REQUIRE(want);
    for (uint32_t z = 0; z < d[2]; z++)
        for (uint32_t y = 0; y < d[1]; y++)
            for (uint32_t x = 0; x < d[0]; x++) {
                size_t i = ip_level_sample_index(p->dims[0], k, x) +
                           (size_t)p->dims[0] *
                               (ip_level_sample_index(p->dims[1], k, y) +
                                (size_t)p->dims[1] * ip_level_sample_index(p->dims[2], k, z));
                want[expected_bin(h, raw[i])]++;
            }
    uint64_t sum = 0;
    int same = 1;
    for (uint32_t b = 0; b < h->bin_count; b++) {
        same &= h->bins[b].count == want[b];
        sum += h->bins[b].count;
    }
    CHECK_MSG(same, "level %u of %s %s: counts differ from the raw samples", k,
              ip_field_name(p->field), ip_type_name(p->type));
    CHECK_EQ(sum + h->unbinned, h->samples);
    CHECK_EQ(h->unbinned, 0);
    CHECK_EQ(h->bricks_read + h->bricks_constant, l->levels[k].brick_count);
    /* edges increase and cover the range */
    CHECK_EQ(h->bins[0].lo, l->value_min);
    CHECK_GE(h->bins[h->bin_count - 1].hi, l->value_max);
    for (uint32_t b = 0; b + 1 < h->bin_count; b++) {
        CHECK_EQ(h->bins[b].hi, h->bins[b + 1].lo);
        CHECK_LT(h->bins[b].lo, h->bins[b].hi);
    }
    /* active sub-blocks: a brute-force count over every sub-block of the level */
    uint32_t per = ip_layout_subblocks_per_brick(l);
    const ip_level_layout *lv = &l->levels[k];
    int active_same = 1;
    uint64_t nonempty = 0;
    for (uint32_t b = 0; b < h->bin_count; b++) {
        double e = h->bins[b].lo;
        uint64_t n = 0;
        for (uint64_t g = lv->first_brick; g < lv->first_brick + lv->brick_count; g++) {
            const float *r = ip_store_subblock_ranges(s, g);
            for (uint32_t i = 0; i < per; i++) {
                n += r[2 * i] < e && e <= r[2 * i + 1];
                nonempty += b == 0 && r[2 * i] <= r[2 * i + 1];
            }
        }
        active_same &= n == h->bins[b].active_subblocks;
    }
    CHECK_MSG(active_same, "level %u: active sub-blocks differ from a direct count", k);
    CHECK_EQ(nonempty, h->subblocks);
    free(want);
    ip_histogram_free(h);
}

/* Every level of a volume with a few bin counts. Returns the number of constant bricks. */
static uint64_t check_volume(const char *dir, const char *stem, const ip_gen_params *p)
{
    char raw_path[4400], ibv[4400];
    test_generate_raw(dir, stem, p, raw_path, sizeof raw_path);
    snprintf(ibv, sizeof ibv, "%s/%s.ibv", dir, stem);
    test_brick_raw(raw_path, ibv, 4, 2);
    size_t count;
    double *raw = read_raw(raw_path, p, &count);
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open(ibv, &s, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < count; i++) {
        lo = raw[i] < lo ? raw[i] : lo;
        hi = raw[i] > hi ? raw[i] : hi;
    }
    CHECK_EQ(lo, l->value_min);
    CHECK_EQ(hi, l->value_max);
    uint64_t constant = 0;
    uint32_t bin_counts[] = {1, 7, 64, 1000};
    for (uint32_t k = 0; k < l->level_count; k++)
        for (size_t b = 0; b < sizeof bin_counts / sizeof bin_counts[0]; b++)
            check_level(s, raw, p, k, bin_counts[b]);
    ip_histogram *h;
    REQUIRE(ip_histogram_compute(s, 0, 64, &h, &err) == IP_OK);
    constant = h->bricks_constant;
    CHECK_LE(h->bin_count, 64);
    if (p->type != IP_FLOAT32) {
        /* whole-value bins: each holds the same number of values */
        double w = h->bins[0].hi - h->bins[0].lo;
        CHECK_EQ(w, floor(w));
        CHECK_EQ(w, ceil((hi - lo + 1) / 64));
        ip_histogram *fine;
        REQUIRE(ip_histogram_compute(s, 0, IP_HISTOGRAM_MAX_BINS, &fine, &err) == IP_OK);
        CHECK_EQ(fine->bin_count, (uint32_t)(hi - lo + 1));
        CHECK_EQ(fine->bins[0].hi - fine->bins[0].lo, 1);
        ip_histogram_free(fine);
    } else {
        if (CHECK_EQ(h->bin_count, 64))
            CHECK_EQ(h->bins[63].hi, l->value_max);
    }
    ip_histogram_free(h);
    ip_store_close(s);
    free(raw);
    return constant;
}

static void check_errors_and_default(const char *dir)
{
    ip_gen_params p = {sizeof(ip_gen_params), IP_FIELD_GYROID, {40, 37, 33}, IP_UINT16, 0.0, 1};
    char raw_path[4400], ibv[4400];
    test_generate_raw(dir, "levels", &p, raw_path, sizeof raw_path);
    snprintf(ibv, sizeof ibv, "%s/levels.ibv", dir);
    test_brick_raw(raw_path, ibv, 4, 2);
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open(ibv, &s, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    REQUIRE(l->level_count >= 3);
    ip_histogram *h = NULL;
    CHECK_EQ(ip_histogram_compute(s, l->level_count, 64, &h, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "levels.ibv");
    CHECK_CONTAINS(err.message, "past the pyramid");
    CHECK_EQ(ip_histogram_compute(s, 0, 0, &h, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "bins");
    CHECK_EQ(ip_histogram_compute(s, 0, IP_HISTOGRAM_MAX_BINS + 1, &h, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(h, NULL);
    /* the default level: the finest within the bound */
    CHECK_EQ(ip_histogram_default_level(l, UINT64_MAX), 0);
    CHECK_EQ(ip_histogram_default_level(l, 0), l->level_count - 1);
    const uint32_t *d1 = l->levels[1].dims;
    uint64_t n1 = (uint64_t)d1[0] * d1[1] * d1[2];
    CHECK_EQ(ip_histogram_default_level(l, n1), 1);
    CHECK_EQ(ip_histogram_default_level(l, n1 - 1), 2);
    CHECK_EQ(ip_histogram_default_level(l, IP_HISTOGRAM_DEFAULT_SAMPLES), 0);
    ip_histogram_free(NULL);
    ip_store_close(s);
}

static const char *scratch_dir;

static void gyroid_volume(void)
{
    ip_gen_params gyroid = {
        sizeof(ip_gen_params), IP_FIELD_GYROID, {21, 18, 19}, IP_UINT16, 0.02, 7};
    check_volume(scratch_dir, "gyroid", &gyroid);
}
static void sphere_volume(void)
{
    ip_gen_params sphere = {sizeof(ip_gen_params), IP_FIELD_SPHERE, {26, 23, 17}, IP_UINT8, 0.0, 1};
    uint64_t constant = check_volume(scratch_dir, "sphere", &sphere);
    CHECK_MSG(constant > 0, "the sphere has no constant brick: that path is not tested");
}
static void phantom_volume(void)
{
    ip_gen_params phantom = {
        sizeof(ip_gen_params), IP_FIELD_SHEPP_LOGAN, {19, 22, 20}, IP_INT16, 0.01, 3};
    check_volume(scratch_dir, "phantom", &phantom);
}
static void lobb_volume(void)
{
    ip_gen_params lobb = {
        sizeof(ip_gen_params), IP_FIELD_MARSCHNER_LOBB, {17, 20, 18}, IP_FLOAT32, 0.0, 1};
    check_volume(scratch_dir, "lobb", &lobb);
}
static void errors_and_default(void)
{
    check_errors_and_default(scratch_dir);
}

static const test_case cases[] = {
    {"check_volume:gyroid", gyroid_volume},           {"check_volume:sphere", sphere_volume},
    {"check_volume:phantom", phantom_volume},         {"check_volume:lobb", lobb_volume},
    {"check_errors_and_default", errors_and_default},
};

static void make_scratch_dir(void)
{
    scratch_dir = test_tmp_dir("test_histogram");
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_histogram", make_scratch_dir, NULL);
}
