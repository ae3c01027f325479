/* SPDX-License-Identifier: BSD-3-Clause */
/* corrupt: exact, fast mutations of brick files, for tools/dev/fault_inject.sh.
 *
 *   corrupt info FILE
 *       prints the file's sections, one per line ("header 0 256", "data OFFSET SIZE",
 *       "gap OFFSET SIZE", "summary OFFSET SIZE", "file_size N"), then one line per brick
 *       that has a payload: "payload G OFFSET SIZE".
 *   corrupt plan FILE [--quick] [--seed N]
 *       prints a deterministic list of mutations, one a line: "CLASS SPEC", where CLASS is
 *       truncate, header-flip, summary-flip, payload-flip, zero-page, append or swap, and
 *       SPEC is what `apply` takes. Positions are spread over the whole of each section and,
 *       for payload flips, over every brick that has a payload.
 *   corrupt apply IN OUT SPEC [--rehash]
 *       writes a copy of IN with one mutation to OUT (which must not exist); with --rehash,
 *       then recomputes every checksum (payloads', summary's, header's) so that the copy
 *       passes them and only what lies behind them can catch the change. SPEC is one of
 *         truncate:LEN           the first LEN bytes only
 *         flip:BIT               bit BIT % 8 of byte BIT / 8 inverted
 *         zero:OFFSET:LEN        LEN bytes from OFFSET set to zero (clipped to the file)
 *         append:LEN:SEED        LEN pseudo-random bytes appended (SEED 0: zero bytes)
 *         swap:A:B:LEN           the LEN bytes at offsets A and B exchanged
 *         set:OFFSET:HEX         the bytes at OFFSET replaced by HEX (e.g. set:40:000000f0)
 *   corrupt inplace FILE SPEC...
 *       applies same-size mutations (flip, zero, swap) to FILE itself with pwrite, without
 *       truncating or replacing it, touching only their bytes: for a file that another
 *       process has open.
 *
 * Exit status: 0 done, 3 the mutation changes nothing (e.g. zeroing zero bytes; OUT is not
 * written), 1 an I/O error or a file that is not a brick file, 2 a bad command line.
 */
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "format.h"
#include "format_offsets.h"
#include "rehash.h"

#define NOOP 3

static int usage(void)
{
    fputs(
        "usage: corrupt info FILE | plan FILE [--quick] [--seed N] | apply IN OUT SPEC [--rehash] | "
        "inplace FILE SPEC...\n",
        stderr);
    return 2;
}

static unsigned char *read_whole(const char *path, uint64_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "corrupt: %s: %s\n", path, strerror(errno));
        return NULL;
    }
    struct stat st;
    if (fstat(fileno(f), &st) != 0) {
        fprintf(stderr, "corrupt: %s: %s\n", path, strerror(errno));
        fclose(f);
        return NULL;
    }
    *size = (uint64_t)st.st_size;
    unsigned char *bytes = malloc(*size + 1);
    if (!bytes || fread(bytes, 1, *size, f) != *size) {
        fprintf(stderr, "corrupt: %s: cannot read\n", path);
        free(bytes);
        fclose(f);
        return NULL;
    }
    fclose(f);
    return bytes;
}

static int write_whole(const char *path, const unsigned char *bytes, uint64_t size)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0) {
        fprintf(stderr, "corrupt: %s: %s\n", path, strerror(errno));
        return 1;
    }
    uint64_t done = 0;
    while (done < size) {
        ssize_t n = write(fd, bytes + done, size - done);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            fprintf(stderr, "corrupt: %s: %s\n", path, strerror(errno));
            close(fd);
            unlink(path);
            return 1;
        }
        done += (uint64_t)n;
    }
    if (close(fd) != 0) {
        fprintf(stderr, "corrupt: %s: %s\n", path, strerror(errno));
        unlink(path);
        return 1;
    }
    return 0;
}

/* The layout of an intact brick file (the one mutations are planned on). */
static int parse(const char *path, const unsigned char *bytes, uint64_t size, ip_layout *l)
{
    ip_error err;
    if (ip__format_parse(bytes, size, path, 0, l, &err) != IP_OK) {
        fprintf(stderr, "corrupt: %s\n", err.message);
        return 1;
    }
    return 0;
}

typedef struct payload {
    uint64_t g, offset, size;
} payload;

/* The bricks that have a payload, in directory order; *count of them. */
static payload *payloads_of(const unsigned char *bytes, const ip_layout *l, uint64_t *count)
{
    ip_summary_offsets so;
    ip__summary_offsets_of(l, &so);
    payload *p = malloc((l->brick_count + 1) * sizeof *p);
    if (!p)
        return NULL;
    *count = 0;
    for (uint64_t g = 0; g < l->brick_count; g++) {
        ip_brick_entry e;
        ip__format_entry_decode(
            bytes + l->summary_offset + so.directory + g * IP_DIRECTORY_ENTRY_SIZE, &e);
        if (e.stored_size > 0)
            p[(*count)++] = (payload){g, e.offset, e.stored_size};
    }
    return p;
}

static int cmd_info(const char *path)
{
    uint64_t size, count;
    ip_layout l;
    unsigned char *bytes = read_whole(path, &size);
    if (!bytes || parse(path, bytes, size, &l) != 0) {
        free(bytes);
        return 1;
    }
    uint64_t data_end = l.data_offset + l.data_size;
    printf("file_size %" PRIu64 "\nheader 0 %u\ndata %" PRIu64 " %" PRIu64 "\n", size,
           IP_HEADER_SIZE, l.data_offset, l.data_size);
    printf("gap %" PRIu64 " %" PRIu64 "\nsummary %" PRIu64 " %" PRIu64 "\n", data_end,
           l.summary_offset - data_end, l.summary_offset, l.summary_size);
    payload *p = payloads_of(bytes, &l, &count);
    for (uint64_t i = 0; p && i < count; i++)
        printf("payload %" PRIu64 " %" PRIu64 " %" PRIu64 "\n", p[i].g, p[i].offset, p[i].size);
    free(p);
    free(bytes);
    return 0;
}

/* splitmix64: a small deterministic generator, so that a plan is the same on every machine. */
static uint64_t next_random(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* A bit flip at a byte spread evenly over [start, start + size): the i-th of n. */
static void plan_flips(const char *cls, uint64_t start, uint64_t size, unsigned n, uint64_t *rng)
{
    if (size == 0)
        return;
    for (unsigned i = 0; i < n; i++) {
        uint64_t lo = size * i / n, hi = size * (i + 1) / n;
        uint64_t byte = start + lo + (hi > lo ? next_random(rng) % (hi - lo) : 0);
        printf("%s flip:%" PRIu64 "\n", cls, byte * 8 + next_random(rng) % 8);
    }
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static int cmd_plan(const char *path, int quick, uint64_t seed)
{
    uint64_t size, count;
    ip_layout l;
    unsigned char *bytes = read_whole(path, &size);
    if (!bytes || parse(path, bytes, size, &l) != 0) {
        free(bytes);
        return 1;
    }
    payload *p = payloads_of(bytes, &l, &count);
    if (!p) {
        free(bytes);
        return 1;
    }
    uint64_t rng = seed;
    uint64_t data_end = l.data_offset + l.data_size;
    ip_summary_offsets so;
    ip__summary_offsets_of(&l, &so);

    /* truncations: the edges of every section, then lengths spread over the data and the
     * summary */
    uint64_t cuts[128];
    unsigned ncut = 0, spread = quick ? 3 : 16;
    uint64_t fixed[] = {0,
                        1,
                        IP_HDR_VERSION,
                        IP_HEADER_SIZE - 1,
                        IP_HEADER_SIZE,
                        IP_HEADER_SIZE + 1,
                        data_end,
                        l.summary_offset - 1,
                        l.summary_offset,
                        l.summary_offset + IP_LEVEL_ENTRY_SIZE,
                        size - 1,
                        size / 2};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
        if (!quick || i % 3 == 0 || fixed[i] == size - 1)
            cuts[ncut++] = fixed[i];
    for (unsigned i = 1; i <= spread; i++)
        cuts[ncut++] = l.data_offset + l.data_size * i / (spread + 1);
    for (unsigned i = 1; i <= spread / 2; i++)
        cuts[ncut++] = l.summary_offset + l.summary_size * i / (spread / 2 + 1);
    qsort(cuts, ncut, sizeof cuts[0], compare_u64);
    for (unsigned i = 0; i < ncut; i++)
        if (cuts[i] < size && (i == 0 || cuts[i] != cuts[i - 1]))
            printf("truncate truncate:%" PRIu64 "\n", cuts[i]);

    /* header: bits spread over all 256 bytes */
    plan_flips("header-flip", 0, IP_HEADER_SIZE, quick ? 8 : 48, &rng);

    /* summary: spread over the whole section, and a few in each of its arrays */
    plan_flips("summary-flip", l.summary_offset, l.summary_size, quick ? 6 : 40, &rng);
    uint64_t arrays[6] = {so.level_table,     so.directory, so.brick_ranges,
                          so.subblock_ranges, so.nodes,     so.end};
    for (int a = 0; a < 5; a++)
        plan_flips("summary-flip", l.summary_offset + arrays[a], arrays[a + 1] - arrays[a],
                   quick ? (a < 2 ? 1 : 0) : 4, &rng);

    /* payloads: round robin over the bricks that have one, at spread positions */
    unsigned flips = quick ? 24 : 200;
    for (unsigned i = 0; i < flips && count > 0; i++) {
        const payload *b = &p[i % count];
        unsigned round = i / (unsigned)count, rounds = (flips + count - 1) / count;
        uint64_t lo = b->size * round / rounds, hi = b->size * (round + 1) / rounds;
        uint64_t byte = b->offset + lo + (hi > lo ? next_random(&rng) % (hi - lo) : 0);
        printf("payload-flip flip:%" PRIu64 "\n", byte * 8 + next_random(&rng) % 8);
    }

    /* zeroed 4 KiB pages: aligned pages that hold data-section bytes, spread; and one of the
     * summary section */
    uint64_t first_page = 0, last_page = (data_end - 1) / 4096;
    uint64_t pages = last_page - first_page + 1;
    unsigned zeros = quick ? 4 : 24;
    if (zeros > pages)
        zeros = (unsigned)pages;
    for (unsigned i = 0; i < zeros; i++) {
        uint64_t page = first_page + (zeros > 1 ? (pages - 1) * i / (zeros - 1) : 0);
        uint64_t start = page * 4096 < IP_HEADER_SIZE ? IP_HEADER_SIZE : page * 4096;
        printf("zero-page zero:%" PRIu64 ":%" PRIu64 "\n", start, (page + 1) * 4096 - start);
    }
    printf("zero-page zero:%" PRIu64 ":4096\n", l.summary_offset);

    /* appended garbage: zeros and random bytes, short and long */
    printf("append append:1:0\n");
    printf("append append:4096:0\n");
    if (!quick) {
        printf("append append:7:%" PRIu64 "\n", seed + 1);
        printf("append append:65539:%" PRIu64 "\n", seed + 2);
        printf("append append:%" PRIu64 ":%" PRIu64 "\n", size, seed + 3);
    }

    /* swapped payloads (the common prefix of two payloads, so sizes need not match) */
    unsigned swaps = quick ? 2 : 8;
    for (unsigned i = 0; i < swaps && count > 1; i++) {
        const payload *a = &p[next_random(&rng) % count];
        const payload *b = &p[next_random(&rng) % count];
        if (a == b)
            b = &p[(uint64_t)(b - p + 1) % count];
        uint64_t n = a->size < b->size ? a->size : b->size;
        printf("swap swap:%" PRIu64 ":%" PRIu64 ":%" PRIu64 "\n", a->offset, b->offset, n);
    }
    free(p);
    free(bytes);
    return 0;
}

static int parse_u64(const char *text, uint64_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(text, &end, 10);
    if (end == text || errno || (*end && *end != ':') || text[0] == '-')
        return -1;
    *out = v;
    return 0;
}

/* Splits "kind:a:b:c" into up to 3 numbers; returns how many, or -1. */
static int parse_spec(const char *spec, char kind[16], uint64_t v[3])
{
    const char *colon = strchr(spec, ':');
    if (!colon || colon - spec >= 16)
        return -1;
    memcpy(kind, spec, (size_t)(colon - spec));
    kind[colon - spec] = '\0';
    int n = 0;
    const char *at = colon + 1;
    while (n < 3) {
        if (parse_u64(at, &v[n]) != 0)
            return -1;
        n++;
        const char *next = strchr(at, ':');
        if (!next)
            return n;
        at = next + 1;
    }
    return -1;
}

/* Mutates `bytes` (*size of them; appending reallocates) in memory; returns 0, NOOP or 2. */
static int hex_digit(char c)
{
    return c >= '0' && c <= '9'   ? c - '0'
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                  : -1;
}

/* set:OFFSET:HEX */
static int mutate_set(unsigned char *b, uint64_t size, const char *spec)
{
    uint64_t offset;
    const char *hex = strchr(spec + 4, ':');
    if (parse_u64(spec + 4, &offset) != 0 || !hex || strlen(hex + 1) % 2 != 0 ||
        strlen(hex + 1) == 0) {
        fprintf(stderr, "corrupt: bad mutation '%s'\n", spec);
        return 2;
    }
    hex++;
    uint64_t n = strlen(hex) / 2;
    if (offset > size || n > size - offset) {
        fprintf(stderr, "corrupt: '%s' reaches past the end of the file\n", spec);
        return 2;
    }
    int changed = 0;
    for (uint64_t i = 0; i < n; i++) {
        int hi = hex_digit(hex[2 * i]), lo = hex_digit(hex[2 * i + 1]);
        if (hi < 0 || lo < 0) {
            fprintf(stderr, "corrupt: bad hex in '%s'\n", spec);
            return 2;
        }
        unsigned char v = (unsigned char)(hi << 4 | lo);
        changed |= b[offset + i] != v;
        b[offset + i] = v;
    }
    return changed ? 0 : NOOP;
}

static int mutate(unsigned char **bytes, uint64_t *size, const char *spec)
{
    if (!strncmp(spec, "set:", 4))
        return mutate_set(*bytes, *size, spec);
    char kind[16];
    uint64_t v[3];
    int n = parse_spec(spec, kind, v);
    unsigned char *b = *bytes;
    if (n == 1 && !strcmp(kind, "truncate")) {
        if (v[0] >= *size)
            return NOOP;
        *size = v[0];
        return 0;
    }
    if (n == 1 && !strcmp(kind, "flip")) {
        if (v[0] / 8 >= *size)
            return 2;
        b[v[0] / 8] ^= (unsigned char)(1u << (v[0] % 8));
        return 0;
    }
    if (n == 2 && !strcmp(kind, "zero")) {
        int changed = 0;
        for (uint64_t i = v[0]; i < v[0] + v[1] && i < *size; i++) {
            changed |= b[i] != 0;
            b[i] = 0;
        }
        return changed ? 0 : NOOP;
    }
    if (n == 2 && !strcmp(kind, "append")) {
        unsigned char *grown = realloc(b, *size + v[0] + 1);
        if (!grown)
            return 2;
        uint64_t rng = v[1];
        for (uint64_t i = 0; i < v[0]; i++)
            grown[*size + i] = v[1] ? (unsigned char)next_random(&rng) : 0;
        *bytes = grown;
        *size += v[0];
        return v[0] ? 0 : NOOP;
    }
    if (n == 3 && !strcmp(kind, "swap")) {
        if (v[0] + v[2] > *size || v[1] + v[2] > *size ||
            (v[0] < v[1] ? v[0] + v[2] > v[1] : v[1] + v[2] > v[0]))
            return 2; /* out of the file, or overlapping */
        if (memcmp(b + v[0], b + v[1], v[2]) == 0)
            return NOOP;
        for (uint64_t i = 0; i < v[2]; i++) {
            unsigned char t = b[v[0] + i];
            b[v[0] + i] = b[v[1] + i];
            b[v[1] + i] = t;
        }
        return 0;
    }
    fprintf(stderr, "corrupt: bad mutation '%s'\n", spec);
    return 2;
}

static int cmd_apply(const char *in, const char *out, const char *spec, int recompute)
{
    uint64_t size;
    unsigned char *bytes = read_whole(in, &size);
    if (!bytes)
        return 1;
    int rc = mutate(&bytes, &size, spec);
    if (rc == 0 && recompute)
        test_rehash(bytes, size);
    if (rc == 0)
        rc = write_whole(out, bytes, size);
    free(bytes);
    return rc;
}

/* Same-size mutations written into the file itself, reading and writing only the bytes
 * they touch (the file may be large, and another process is reading it meanwhile).
 * Returns 0 when something changed, NOOP when nothing did, 1 or 2 on errors. */
static int inplace_one(int fd, uint64_t size, const char *spec)
{
    char kind[16];
    uint64_t v[3];
    int n = parse_spec(spec, kind, v);
    unsigned char *a = NULL, *b = NULL;
    int rc = 2;
    if (n == 1 && !strcmp(kind, "flip") && v[0] / 8 < size) {
        unsigned char byte;
        if (pread(fd, &byte, 1, (off_t)(v[0] / 8)) != 1)
            return 1;
        byte ^= (unsigned char)(1u << (v[0] % 8));
        return pwrite(fd, &byte, 1, (off_t)(v[0] / 8)) == 1 ? 0 : 1;
    }
    if (n == 2 && !strcmp(kind, "zero") && v[0] < size) {
        uint64_t len = v[1] < size - v[0] ? v[1] : size - v[0];
        a = malloc(len + 1);
        b = calloc(len + 1, 1);
        if (!a || !b || pread(fd, a, len, (off_t)v[0]) != (ssize_t)len)
            rc = 1;
        else if (memcmp(a, b, len) == 0)
            rc = NOOP;
        else
            rc = pwrite(fd, b, len, (off_t)v[0]) == (ssize_t)len ? 0 : 1;
    } else if (n == 3 && !strcmp(kind, "swap") && v[0] + v[2] <= size && v[1] + v[2] <= size &&
               (v[0] < v[1] ? v[0] + v[2] <= v[1] : v[1] + v[2] <= v[0])) {
        a = malloc(v[2] + 1);
        b = malloc(v[2] + 1);
        if (!a || !b || pread(fd, a, v[2], (off_t)v[0]) != (ssize_t)v[2] ||
            pread(fd, b, v[2], (off_t)v[1]) != (ssize_t)v[2])
            rc = 1;
        else if (memcmp(a, b, v[2]) == 0)
            rc = NOOP;
        else
            rc = pwrite(fd, b, v[2], (off_t)v[0]) == (ssize_t)v[2] &&
                         pwrite(fd, a, v[2], (off_t)v[1]) == (ssize_t)v[2]
                     ? 0
                     : 1;
    } else {
        fprintf(stderr, "corrupt: inplace takes flip, zero or swap inside the file, not '%s'\n",
                spec);
    }
    free(a);
    free(b);
    return rc;
}

static int cmd_inplace(const char *path, char **specs, int count)
{
    int fd = open(path, O_RDWR);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        fprintf(stderr, "corrupt: %s: %s\n", path, strerror(errno));
        if (fd >= 0)
            close(fd);
        return 1;
    }
    int changed = 0, rc = 0;
    for (int i = 0; i < count && (rc == 0 || rc == NOOP); i++) {
        rc = inplace_one(fd, (uint64_t)st.st_size, specs[i]);
        changed |= rc == 0;
        if (rc == 1)
            fprintf(stderr, "corrupt: %s: %s: %s\n", path, specs[i], strerror(errno));
    }
    if (close(fd) != 0 && (rc == 0 || rc == NOOP)) {
        fprintf(stderr, "corrupt: %s: %s\n", path, strerror(errno));
        rc = 1;
    }
    if (rc == 0 || rc == NOOP)
        rc = changed ? 0 : NOOP;
    return rc;
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "info"))
        return cmd_info(argv[2]);
    if (argc >= 3 && !strcmp(argv[1], "plan")) {
        int quick = 0;
        uint64_t seed = 1;
        for (int i = 3; i < argc; i++) {
            if (!strcmp(argv[i], "--quick"))
                quick = 1;
            else if (!strcmp(argv[i], "--seed") && i + 1 < argc)
                seed = strtoull(argv[++i], NULL, 10);
            else
                return usage();
        }
        return cmd_plan(argv[2], quick, seed);
    }
    if ((argc == 5 || (argc == 6 && !strcmp(argv[5], "--rehash"))) && !strcmp(argv[1], "apply"))
        return cmd_apply(argv[2], argv[3], argv[4], argc == 6);
    if (argc >= 4 && !strcmp(argv[1], "inplace"))
        return cmd_inplace(argv[2], argv + 3, argc - 3);
    return usage();
}
