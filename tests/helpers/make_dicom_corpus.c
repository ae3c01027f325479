/* SPDX-License-Identifier: BSD-3-Clause */
/* make_dicom_corpus: writes the seed inputs of the DICOM fuzz harness (tests/fuzz/fuzz_dicom.c):
 * small valid series (dicom_series.h) in each transfer syntax the tests write, encoded in the
 * harness's input layout: slice 0 is the template, and each other slice the edits that turn the
 * template into it (its UIDs, instance number, position and pixels), or one edit holding the
 * whole file when its length differs (another transfer syntax). Some seeds also hold
 * sequences (a Referenced Image Sequence, an Icon Image Sequence with its own small image), so
 * that the harness starts from items, delimiters and nested elements too.
 *
 *   make_dicom_corpus DIR    writes DIR/series_*, the seeds (DIR must exist)
 *
 * tests/fuzz/corpus_fuzz_dicom/ holds its output, plus the inputs the harness found (named
 * found_*); the ctest test dicom_corpus checks that the seeds there are this program's.
 * Exit status: 0 done, 1 a file could not be written, 2 a bad command line. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* deflated data sets in stored blocks: the same bytes whatever the zlib version, and bytes
 * that a mutation changes one for one */
#define TEST_DICOM_DEFLATE_LEVEL Z_NO_COMPRESSION
#include "dicom_series.h"

/* Runs of differing bytes closer than this are one edit. */
#define EDIT_GAP 8

static void put16(test_bytes *out, size_t value)
{
    unsigned char b[2] = {(unsigned char)value, (unsigned char)(value >> 8)};
    test_bytes_put(out, b, 2);
}

/* One edit of the harness's layout: slice, offset, bytes removed, bytes inserted. */
static void put_edit(test_bytes *out, unsigned slice, size_t offset, size_t removed,
                     const unsigned char *inserted, size_t inserted_size)
{
    unsigned char index = (unsigned char)slice;
    REQUIRE(offset <= 0xFFFF && removed <= 0xFFFF && inserted_size <= 0xFFFF);
    test_bytes_put(out, &index, 1);
    put16(out, offset);
    put16(out, removed);
    put16(out, inserted_size);
    test_bytes_put(out, inserted, inserted_size);
}

/* The edits that turn `template` into `target`: byte runs where the two differ (same length),
 * else the whole file. */
static void put_edits(test_bytes *out, unsigned slice, const test_bytes *template,
                      const test_bytes *target)
{
    if (template->size != target->size) {
        put_edit(out, slice, 0, template->size, target->data, target->size);
        return;
    }
    size_t i = 0;
    while (i < target->size) {
        if (template->data[i] == target->data[i]) {
            i++;
            continue;
        }
        size_t end = i + 1, same = 0;
        for (size_t j = i + 1; j < target->size && same < EDIT_GAP; j++) {
            if (template->data[j] == target->data[j]) {
                same++;
            } else {
                same = 0;
                end = j + 1;
            }
        }
        put_edit(out, slice, i, end - i, target->data + i, end - i);
        i = end;
    }
}

/* A volume whose samples differ from slice to slice; signed ones go negative. */
static void *make_volume(const test_dicom_series *s)
{
    size_t count = (size_t)s->dims[0] * s->dims[1] * s->dims[2];
    unsigned char *v = malloc(count * ip_type_size(s->type));
    REQUIRE(v != NULL);
    for (size_t i = 0; i < count; i++) {
        if (s->type == IP_UINT8)
            v[i] = (unsigned char)(i * 37 + 11);
        else if (s->type == IP_UINT16)
            ((uint16_t *)v)[i] = (uint16_t)(i * 2741 + 300);
        else
            ((int16_t *)v)[i] = (int16_t)((int)(i * 97 % 3000) - 1500);
    }
    return v;
}

/* One seed: the series `s` (positions 10, 12, 14, ... mm, so that every slice's position text
 * has the length of the first's) with the harness's `flags`, as DIR/name. */
static int write_seed(const char *dir, const char *name, test_dicom_series s, unsigned flags)
{
    char path[4200];
    test_bytes out = {0}, template = {0};
    void *volume = make_volume(&s);
    unsigned char head[2] = {(unsigned char)(s.dims[2] - 2), (unsigned char)flags};
    REQUIRE(s.dims[2] >= 2 && s.dims[2] <= 4);
    test_dicom_slice_bytes(&s, volume, 0, &template);
    test_bytes_put(&out, head, 2);
    put16(&out, template.size);
    test_bytes_put(&out, template.data, template.size);
    for (uint32_t z = 1; z < s.dims[2]; z++) {
        test_bytes slice = {0};
        test_dicom_slice_bytes(&s, volume, z, &slice);
        put_edits(&out, z, &template, &slice);
        free(slice.data);
    }
    snprintf(path, sizeof path, "%.4000s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(out.data, 1, out.size, f) == out.size;
    if (f && fclose(f) != 0)
        ok = 0;
    if (!ok)
        fprintf(stderr, "make_dicom_corpus: %s: cannot write\n", path);
    free(template.data);
    free(out.data);
    free(volume);
    return ok ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fputs("usage: make_dicom_corpus DIR\n", stderr);
        return 2;
    }
    const struct {
        const char *name, *syntax; /* syntax NULL: the four by turns */
        ip_type type;
        uint32_t slices;
        unsigned flags;
        int sequences; /* a Referenced Image Sequence and an Icon Image Sequence */
    } seeds[] = {
        {"series_explicit_le_uint16", TEST_DICOM_EXPLICIT_LE, IP_UINT16, 3, 0, 0},
        {"series_explicit_le_uint8", TEST_DICOM_EXPLICIT_LE, IP_UINT8, 4, 0, 0},
        {"series_implicit_le_int16", TEST_DICOM_IMPLICIT_LE, IP_INT16, 3, 0, 0},
        {"series_implicit_le_uint8", TEST_DICOM_IMPLICIT_LE, IP_UINT8, 2, 0, 0},
        {"series_explicit_be_int16", TEST_DICOM_EXPLICIT_BE, IP_INT16, 2, 0, 0},
        {"series_explicit_be_uint16", TEST_DICOM_EXPLICIT_BE, IP_UINT16, 4, 1, 0},
        {"series_rle_uint16", TEST_DICOM_RLE, IP_UINT16, 3, 0, 0},
        {"series_rle_uint8", TEST_DICOM_RLE, IP_UINT8, 2, 0, 0},
        {"series_rle_int16", TEST_DICOM_RLE, IP_INT16, 4, 0, 0},
        {"series_deflate_uint16", TEST_DICOM_DEFLATE, IP_UINT16, 3, 0, 0},
        {"series_deflate_uint8", TEST_DICOM_DEFLATE, IP_UINT8, 2, 0, 0},
        {"series_mixed_syntaxes_int16", NULL, IP_INT16, 4, 0, 0},
        {"series_index_and_hidden_uint16", TEST_DICOM_EXPLICIT_LE, IP_UINT16, 2, 2 | 4, 0},
        {"series_sequences_explicit_le_uint16", TEST_DICOM_EXPLICIT_LE, IP_UINT16, 3, 0, 1},
        {"series_sequences_implicit_le_int16", TEST_DICOM_IMPLICIT_LE, IP_INT16, 2, 0, 1},
        {"series_sequences_explicit_be_uint16", TEST_DICOM_EXPLICIT_BE, IP_UINT16, 2, 0, 1},
        {"series_sequences_rle_uint8", TEST_DICOM_RLE, IP_UINT8, 3, 0, 1},
    };
    int status = 0;
    for (size_t i = 0; i < sizeof seeds / sizeof seeds[0]; i++) {
        test_dicom_series s = test_dicom_default(4, 3, seeds[i].slices, seeds[i].type);
        s.syntax = seeds[i].syntax;
        s.sequences = seeds[i].sequences;
        s.origin_z = 10, s.step_z = 2;
        status |= write_seed(argv[1], seeds[i].name, s, seeds[i].flags);
    }
    return status;
}
