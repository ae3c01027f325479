/* SPDX-License-Identifier: BSD-3-Clause */
/* Writes HDF5 files of a uint16 raw volume's samples with libhdf5, for tests/tools/hdf5.sh:
 *
 *   make_hdf5 NAME_XxYxZ_uint16.raw DIR
 *
 * DIR/contiguous.h5   /volume, contiguous uint16, attribute element_size_um = 1.25,0.5,0.5
 * DIR/chunked.h5      /data/volume, chunks of 5x16x8 (z,y,x: partial chunks at every edge),
 *                     shuffle + gzip, attribute spacing = 1.25,0.5,0.5
 * DIR/two.h5          /a (the samples + 1000) and /b/c (the samples), both 3-D, and a 2-D
 *                     /image; no spacing attribute
 * DIR/int32.h5        /volume as int32, chunked + gzip, element_size_um as above
 * DIR/float64.h5      /volume as big-endian float64, element_size_um as above
 * DIR/int64.h5        /volume as int64 (a type that is refused)
 * DIR/flat.h5         a 2-D dataset only
 * DIR/truncated.h5    chunked.h5 cut to half its length
 * DIR/damaged.h5      chunked.h5 with 64 bytes of its last chunk's data overwritten
 * DIR/NAME_XxYxZ_float32.raw  the samples as float32 (what int32 and float64 brick as)
 *
 *   make_hdf5 --chunked EDGE RAW OUT.h5
 *
 * writes RAW's samples (any type) as /volume of OUT.h5 in chunks of EDGE^3 with gzip (deflate
 * level 4, no shuffle), EDGE planes at a time, so that memory stays one layer of chunks
 * (tools/bench/bench_hdf5.sh).
 */
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "isoprop/input.h"

static const double spacing_zyx[3] = {1.25, 0.5, 0.5};

static int fail(const char *what)
{
    fprintf(stderr, "make_hdf5: %s\n", what);
    return 1;
}

static void spacing_attribute(hid_t d, const char *name)
{
    hsize_t three = 3;
    hid_t space = H5Screate_simple(1, &three, NULL);
    hid_t a = H5Acreate2(d, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_DOUBLE, spacing_zyx);
    H5Aclose(a);
    H5Sclose(space);
}

/* Writes `data` (memory type mem) as dataset `name` of file type `file_type`; chunk NULL:
 * contiguous. */
static int write_dataset(hid_t file, const char *name, int rank, const hsize_t *dims,
                         hid_t file_type, hid_t mem, const void *data, const hsize_t *chunk,
                         const char *spacing)
{
    hid_t space = H5Screate_simple(rank, dims, NULL);
    hid_t lcpl = H5Pcreate(H5P_LINK_CREATE), dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_create_intermediate_group(lcpl, 1);
    if (chunk) {
        H5Pset_chunk(dcpl, rank, chunk);
        H5Pset_shuffle(dcpl);
        H5Pset_deflate(dcpl, 6);
    }
    hid_t d = H5Dcreate2(file, name, file_type, space, lcpl, dcpl, H5P_DEFAULT);
    int bad = d < 0 || H5Dwrite(d, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0;
    if (!bad && spacing)
        spacing_attribute(d, spacing);
    if (d >= 0)
        H5Dclose(d);
    H5Pclose(dcpl);
    H5Pclose(lcpl);
    H5Sclose(space);
    return bad;
}

static hid_t create(const char *dir, const char *name)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
}

/* Copies DIR/chunked.h5 to DIR/name, cut to half its length (truncate) or with 64 bytes of
 * its last chunk overwritten. */
static int damaged_copy(const char *dir, const char *name, int truncate)
{
    char in[4096], out[4096];
    snprintf(in, sizeof in, "%s/chunked.h5", dir);
    snprintf(out, sizeof out, "%s/%s", dir, name);
    FILE *f = fopen(in, "rb");
    if (!f)
        return 1;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    rewind(f);
    unsigned char *bytes = malloc((size_t)size);
    int bad = !bytes || fread(bytes, 1, (size_t)size, f) != (size_t)size;
    fclose(f);
    if (!bad) {
        if (!truncate)
            memset(bytes + size - 200, 0x5a, 64); /* chunks are written after the metadata */
        f = fopen(out, "wb");
        bad = !f || fwrite(bytes, 1, (size_t)(truncate ? size / 2 : size), f) == 0;
        if (f)
            fclose(f);
    }
    free(bytes);
    return bad;
}

static int write_files(const char *dir, const uint32_t d[3], const uint16_t *s, size_t n)
{
    hsize_t dims[3] = {d[2], d[1], d[0]}, chunk[3] = {5, 16, 8};
    int32_t *i32 = malloc(n * sizeof *i32);
    double *f64 = malloc(n * sizeof *f64);
    uint16_t *plus = malloc(n * sizeof *plus);
    if (!i32 || !f64 || !plus)
        return 1;
    for (size_t i = 0; i < n; i++) {
        i32[i] = s[i];
        f64[i] = s[i];
        plus[i] = (uint16_t)(s[i] + 1000);
    }
    /* one row a dataset; a row naming the file of the row before adds to that file */
    const struct {
        const char *file, *name;
        int rank;
        hid_t type, mem;
        const void *data;
        const hsize_t *chunk;
        const char *spacing;
    } rows[] = {
        {"contiguous.h5", "/volume", 3, H5T_STD_U16LE, H5T_NATIVE_UINT16, s, NULL,
         "element_size_um"},
        {"chunked.h5", "/data/volume", 3, H5T_STD_U16LE, H5T_NATIVE_UINT16, s, chunk, "spacing"},
        {"two.h5", "/a", 3, H5T_STD_U16LE, H5T_NATIVE_UINT16, plus, NULL, NULL},
        {"two.h5", "/b/c", 3, H5T_STD_U16BE, H5T_NATIVE_UINT16, s, chunk, NULL},
        {"two.h5", "/image", 2, H5T_STD_U16LE, H5T_NATIVE_UINT16, s, NULL, NULL},
        {"int32.h5", "/volume", 3, H5T_STD_I32LE, H5T_NATIVE_INT32, i32, chunk, "element_size_um"},
        {"float64.h5", "/volume", 3, H5T_IEEE_F64BE, H5T_NATIVE_DOUBLE, f64, NULL,
         "element_size_um"},
        {"int64.h5", "/volume", 3, H5T_STD_I64LE, H5T_NATIVE_INT32, i32, NULL, NULL},
        {"flat.h5", "/image", 2, H5T_STD_U16LE, H5T_NATIVE_UINT16, s, NULL, NULL},
    };
    int bad = 0;
    hid_t f = -1;
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        if (i == 0 || strcmp(rows[i].file, rows[i - 1].file) != 0) {
            if (f >= 0)
                H5Fclose(f);
            f = create(dir, rows[i].file);
        }
        /* a 2-D dataset: the y-x extent of the volume's first plane */
        bad |= write_dataset(f, rows[i].name, rows[i].rank, dims + 3 - rows[i].rank, rows[i].type,
                             rows[i].mem, rows[i].data, rows[i].chunk, rows[i].spacing);
    }
    H5Fclose(f);
    bad |= damaged_copy(dir, "truncated.h5", 1) | damaged_copy(dir, "damaged.h5", 0);
    free(i32);
    free(f64);
    free(plus);
    return bad;
}

/* The samples as float32, little-endian, named as isobrick reads them. */
static int write_float32(const char *dir, const uint32_t d[3], const uint16_t *s, size_t n)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/volume_%ux%ux%u_float32.raw", dir, d[0], d[1], d[2]);
    FILE *f = fopen(path, "wb");
    if (!f)
        return 1;
    int bad = 0;
    for (size_t i = 0; i < n && !bad; i++) {
        float v = s[i];
        bad = fwrite(&v, sizeof v, 1, f) != 1;
    }
    return fclose(f) != 0 || bad;
}

/* RAW as one chunked, gzip-compressed dataset, a layer of chunks at a time. */
static int write_chunked(const char *raw, uint32_t edge, const char *out)
{
    ip_input_desc desc;
    ip_input_reader *reader;
    ip_error err;
    static const int file_types[] = {
        [IP_UINT8] = 0, [IP_UINT16] = 1, [IP_INT16] = 2, [IP_FLOAT32] = 3};
    if (edge == 0 || ip_input_describe(raw, NULL, &desc, &err) != IP_OK ||
        ip_input_open(&desc, &reader, &err) != IP_OK)
        return fail("cannot read the input");
    hid_t types[4] = {H5T_NATIVE_UINT8, H5T_NATIVE_UINT16, H5T_NATIVE_INT16, H5T_NATIVE_FLOAT};
    hid_t type = types[file_types[desc.type]];
    hsize_t dims[3] = {desc.dims[2], desc.dims[1], desc.dims[0]}, chunk[3] = {edge, edge, edge};
    for (int axis = 0; axis < 3; axis++)
        chunk[axis] = chunk[axis] < dims[axis] ? chunk[axis] : dims[axis];
    size_t plane = (size_t)desc.dims[0] * desc.dims[1] * ip_type_size(desc.type);
    unsigned char *buf = malloc(plane * chunk[0]);
    hid_t file = H5Fcreate(out, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hid_t space = H5Screate_simple(3, dims, NULL), dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 3, chunk);
    H5Pset_deflate(dcpl, 4);
    hid_t d = H5Dcreate2(file, "/volume", type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    int bad = !buf || d < 0;
    for (hsize_t z = 0; !bad && z < dims[0]; z += chunk[0]) {
        hsize_t start[3] = {z, 0, 0}, size[3] = {chunk[0], dims[1], dims[2]};
        if (size[0] > dims[0] - z)
            size[0] = dims[0] - z;
        hid_t memory = H5Screate_simple(3, size, NULL);
        bad = ip_input_read_planes(reader, buf, (uint32_t)size[0], &err) != IP_OK ||
              H5Sselect_hyperslab(space, H5S_SELECT_SET, start, NULL, size, NULL) < 0 ||
              H5Dwrite(d, type, memory, space, H5P_DEFAULT, buf) < 0;
        H5Sclose(memory);
    }
    H5Dclose(d);
    H5Pclose(dcpl);
    H5Sclose(space);
    bad |= H5Fclose(file) < 0;
    ip_input_close(reader);
    free(buf);
    return bad ? fail("cannot write the chunked file") : 0;
}

int main(int argc, char **argv)
{
    ip_input_desc desc;
    ip_input_reader *reader;
    ip_error err;
    if (argc == 5 && strcmp(argv[1], "--chunked") == 0) {
        H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
        return write_chunked(argv[3], (uint32_t)strtoul(argv[2], NULL, 10), argv[4]);
    }
    if (argc != 3)
        return fail("usage: make_hdf5 NAME_XxYxZ_uint16.raw DIR");
    if (ip_input_describe(argv[1], NULL, &desc, &err) != IP_OK || desc.type != IP_UINT16)
        return fail("the input is not a uint16 raw volume");
    size_t n = (size_t)desc.dims[0] * desc.dims[1] * desc.dims[2];
    uint16_t *s = malloc(n * sizeof *s);
    if (!s || ip_input_open(&desc, &reader, &err) != IP_OK)
        return fail("cannot read the input");
    ip_status st = ip_input_read_planes(reader, s, desc.dims[2], &err);
    ip_input_close(reader);
    if (st != IP_OK)
        return fail(err.message);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    int bad = write_files(argv[2], desc.dims, s, n) || write_float32(argv[2], desc.dims, s, n);
    free(s);
    return bad ? fail("cannot write the files") : 0;
}
