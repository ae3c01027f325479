/* SPDX-License-Identifier: BSD-3-Clause */
/* HDF5 input through libhdf5 (serial): one 3-D dataset of a file, dims (z, y, x) in C order
 * (x fastest), contiguous or chunked with any filter this libhdf5 decodes. The planes are read
 * a slab at a time: a layer of chunks (the chunk's height along z, a hyperslab on chunk
 * boundaries, so that each chunk is decoded once), or about 16 MiB of planes of a contiguous
 * dataset; memory is that slab. Gzip chunks in the host's byte order are read as stored and
 * inflated on several threads (chunk_inflate.c); libhdf5 decodes every other filter. Samples of the types the library stores are copied; int8 is
 * widened to int16, int32 and uint32 become float32 (refused, naming the sample, where float32
 * does not hold the value exactly), float64 becomes float32 (rounded; refused beyond float32's
 * range). libhdf5's own printing of its error stack is turned off (H5Eset_auto2) and its
 * errors become one line naming the file and the dataset. libhdf5 may be built without thread
 * safety: every call into it here holds one lock. Built without HDF5 (IP_HDF5=OFF), an HDF5 input is
 * refused with one line naming what to install. */
#include <float.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "readers.h"
#include "internal.h"

#ifdef IP_HAVE_HDF5

#include <hdf5.h>
#include <pthread.h>

#include "chunk_inflate.h"

/* Planes of a contiguous dataset read at once: about this many bytes (at least one plane). */
#define CONTIGUOUS_SLAB_BYTES ((size_t)16 << 20)
/* The 3-D datasets a refusal lists at most. */
#define LIST_MAX 16

static pthread_mutex_t hdf5_lock = PTHREAD_MUTEX_INITIALIZER;

/* Around every use of libhdf5: the lock, and its error printing off. A thread-safe libhdf5
 * keeps that setting per thread, and the bricker may read on a thread of its own. */
static void hdf5_enter(void)
{
    pthread_mutex_lock(&hdf5_lock);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static void hdf5_leave(void)
{
    pthread_mutex_unlock(&hdf5_lock);
}

/* The sample types read, as the file stores them. */
typedef enum sample_kind {
    K_U8,
    K_I8,
    K_U16,
    K_I16,
    K_U32,
    K_I32,
    K_F32,
    K_F64
} sample_kind;

static const char *const kind_names[] = {"uint8",  "int8",  "uint16",  "int16",
                                         "uint32", "int32", "float32", "float64"};
static const size_t kind_sizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
static const ip_type kind_stored[] = {IP_UINT8,   IP_INT16,   IP_UINT16,  IP_INT16,
                                      IP_FLOAT32, IP_FLOAT32, IP_FLOAT32, IP_FLOAT32};

static hid_t kind_native(sample_kind k)
{
    switch (k) {
    case K_U8: return H5T_NATIVE_UINT8;
    case K_I8: return H5T_NATIVE_INT8;
    case K_U16: return H5T_NATIVE_UINT16;
    case K_I16: return H5T_NATIVE_INT16;
    case K_U32: return H5T_NATIVE_UINT32;
    case K_I32: return H5T_NATIVE_INT32;
    case K_F32: return H5T_NATIVE_FLOAT;
    case K_F64: break;
    }
    return H5T_NATIVE_DOUBLE;
}

/* The kind of the dataset type `t`, or -1 with its description in `what`. */
static int kind_of(hid_t t, char *what, size_t size)
{
    H5T_class_t c = H5Tget_class(t);
    size_t bytes = H5Tget_size(t);
    if (c == H5T_INTEGER) {
        int is_signed = H5Tget_sign(t) == H5T_SGN_2;
        switch (bytes) {
        case 1: return is_signed ? K_I8 : K_U8;
        case 2: return is_signed ? K_I16 : K_U16;
        case 4: return is_signed ? K_I32 : K_U32;
        default: break;
        }
        snprintf(what, size, "%s %zu-bit integers", is_signed ? "signed" : "unsigned", 8 * bytes);
        return -1;
    }
    if (c == H5T_FLOAT && (bytes == 4 || bytes == 8))
        return bytes == 4 ? K_F32 : K_F64;
    static const char *const classes[] = {
        "integers",    "floats",    "times",      "strings",      "bit fields",
        "opaque data", "compounds", "references", "enumerations", "variable-length data",
        "arrays"};
    if (c == H5T_FLOAT)
        snprintf(what, size, "%zu-bit floats", 8 * bytes);
    else
        snprintf(what, size, "%s", c >= 0 && c < 11 ? classes[c] : "of an unknown class");
    return -1;
}

/* ---- libhdf5's errors as one line ---- */

static herr_t keep_deepest(unsigned n, const H5E_error2_t *e, void *data)
{
    (void)n;
    if (e->desc && e->desc[0])
        snprintf(data, 256, "%s", e->desc);
    return 0;
}

/* The innermost description on libhdf5's error stack (clearing it) into why[256]. */
static const char *hdf5_reason(char why[256])
{
    why[0] = '\0';
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, keep_deepest, why);
    H5Eclear2(H5E_DEFAULT);
    for (char *c = why; *c; c++)
        if (*c == '\n' || *c == '\r')
            *c = ' ';
    if (!why[0])
        snprintf(why, 256, "libhdf5 gives no reason");
    return why;
}

/* Opens `path` read-only (a regular file: a FIFO is refused, never waited on). */
static ip_status open_file(const char *path, hid_t *file, ip_error *err)
{
    char why[256];
    int fd;
    ip_status st = ip__input_open_regular(path, &fd, err);
    if (st != IP_OK)
        return st;
    close(fd);
    *file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (*file < 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: not a readable HDF5 file (%s)", path,
                        hdf5_reason(why));
    return IP_OK;
}

/* ---- finding the 3-D datasets ---- */

typedef struct dataset_entry {
    char path[IP_DATASET_MAX + 1]; /* IP_DATASET_MAX characters: longer than a desc holds */
    hsize_t dims[3];
    char type[40];
} dataset_entry;

typedef struct dataset_list {
    dataset_entry items[LIST_MAX];
    unsigned count, total;
} dataset_list;

/* The rank, dims (up to 3) and type name of dataset `d`; the rank, or -1. */
static int dataset_shape(hid_t d, hsize_t dims[3], char *type, size_t size, int *kind)
{
    hid_t space = H5Dget_space(d), t = H5Dget_type(d);
    int rank = space >= 0 ? H5Sget_simple_extent_ndims(space) : -1;
    if (rank == 3)
        H5Sget_simple_extent_dims(space, dims, NULL);
    *kind = t >= 0 ? kind_of(t, type, size) : -1;
    if (*kind >= 0)
        snprintf(type, size, "%s", kind_names[*kind]);
    if (t >= 0)
        H5Tclose(t);
    if (space >= 0)
        H5Sclose(space);
    return rank;
}

static herr_t visit_link(hid_t group, const char *name, const H5L_info_t *info, void *data)
{
    dataset_list *list = data;
    if (info->type != H5L_TYPE_HARD)
        return 0;
    hid_t obj = H5Oopen(group, name, H5P_DEFAULT);
    if (obj < 0) {
        H5Eclear2(H5E_DEFAULT);
        return 0;
    }
    dataset_entry e;
    int kind;
    if (H5Iget_type(obj) == H5I_DATASET &&
        dataset_shape(obj, e.dims, e.type, sizeof e.type, &kind) == 3) {
        if (list->count < LIST_MAX) {
            snprintf(list->items[list->count].path, sizeof e.path, "/%s", name);
            memcpy(list->items[list->count].dims, e.dims, sizeof e.dims);
            memcpy(list->items[list->count].type, e.type, sizeof e.type);
            list->count++;
        }
        list->total++;
    }
    H5Oclose(obj);
    return 0;
}

/* The 3-D datasets as "/a (ZxYxX uint16), /b (...)" into text; those that do not fit, and
 * those past LIST_MAX, are counted at the end. */
static void list_text(const dataset_list *list, char *text, size_t size)
{
    size_t used = 0;
    text[0] = '\0';
    unsigned shown = 0;
    for (; shown < list->count; shown++) {
        const dataset_entry *e = &list->items[shown];
        char item[IP_DATASET_MAX + 96];
        snprintf(item, sizeof item, "%s%s (z,y,x %llux%llux%llu, %s)", shown ? ", " : "", e->path,
                 (unsigned long long)e->dims[0], (unsigned long long)e->dims[1],
                 (unsigned long long)e->dims[2], e->type);
        if (used + strlen(item) + 24 >= size)
            break;
        memcpy(text + used, item, strlen(item) + 1);
        used += strlen(item);
    }
    if (shown < list->total)
        snprintf(text + used, size - used, "%sand %u more", shown ? ", " : "", list->total - shown);
}

/* The dataset to read into name: the one asked for, else the file's only 3-D dataset. */
static ip_status pick_dataset(hid_t file, const char *path, const char *asked,
                              char name[IP_DATASET_MAX], ip_error *err)
{
    char text[640];
    dataset_list *list = calloc(1, sizeof *list);
    if (!list)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    if (H5Lvisit(file, H5_INDEX_NAME, H5_ITER_INC, visit_link, list) < 0)
        H5Eclear2(H5E_DEFAULT);
    list_text(list, text, sizeof text);
    ip_status st = IP_OK;
    if (asked) {
        hid_t d = strlen(asked) < IP_DATASET_MAX ? H5Dopen2(file, asked, H5P_DEFAULT) : -1;
        if (d < 0) {
            H5Eclear2(H5E_DEFAULT);
            st = ip__fail(err, IP_ERR_INPUT,
                          "%s: no dataset %.*s%s in the file (its 3-D datasets: %s)", path,
                          IP_DATASET_MAX, asked,
                          strlen(asked) < IP_DATASET_MAX ? "" : "... (too long a path)",
                          list->total ? text : "none");
        } else {
            H5Dclose(d);
            snprintf(name, IP_DATASET_MAX, "%s", asked);
        }
    } else if (list->total == 1 && strlen(list->items[0].path) < IP_DATASET_MAX) {
        snprintf(name, IP_DATASET_MAX, "%s", list->items[0].path);
    } else if (list->total == 0) {
        st = ip__fail(err, IP_ERR_INPUT, "%s: the HDF5 file holds no 3-D dataset", path);
    } else {
        st = ip__fail(err, IP_ERR_INPUT, "%s: %u 3-D datasets: pick one with --dataset: %s", path,
                      list->total, text);
    }
    free(list);
    return st;
}

/* ---- the dataset's shape, type, filters and spacing ---- */

/* Every filter of the dataset must be one this libhdf5 can apply. */
static ip_status check_filters(hid_t d, const char *path, const char *name, ip_error *err)
{
    hid_t dcpl = H5Dget_create_plist(d);
    int n = dcpl >= 0 ? H5Pget_nfilters(dcpl) : 0;
    ip_status st = IP_OK;
    for (int i = 0; st == IP_OK && i < n; i++) {
        unsigned flags = 0;
        size_t values = 0;
        char filter[64] = "";
        H5Z_filter_t id =
            H5Pget_filter2(dcpl, (unsigned)i, &flags, &values, NULL, sizeof filter, filter, NULL);
        if (id < 0 || H5Zfilter_avail(id) <= 0)
            st = ip__fail(err, IP_ERR_UNSUPPORTED,
                          "%s: dataset %s: stored with HDF5 filter %d (%s), which this libhdf5 "
                          "cannot decode",
                          path, name, (int)id, filter[0] ? filter : "unnamed");
    }
    H5Eclear2(H5E_DEFAULT);
    if (dcpl >= 0)
        H5Pclose(dcpl);
    return st;
}

/* Attribute `attr` of `d` as three numbers in (z, y, x) order into spacing (x, y, z): 1 when
 * read, 0 when absent, -1 when it is not three numbers. */
static int read_spacing_attr(hid_t d, const char *attr, double spacing[3])
{
    if (H5Aexists(d, attr) <= 0)
        return 0;
    hid_t a = H5Aopen(d, attr, H5P_DEFAULT), space = a >= 0 ? H5Aget_space(a) : -1;
    hid_t t = a >= 0 ? H5Aget_type(a) : -1;
    double v[3];
    int ok = space >= 0 && t >= 0 && H5Sget_simple_extent_npoints(space) == 3 &&
             (H5Tget_class(t) == H5T_INTEGER || H5Tget_class(t) == H5T_FLOAT) &&
             H5Aread(a, H5T_NATIVE_DOUBLE, v) >= 0;
    if (t >= 0)
        H5Tclose(t);
    if (space >= 0)
        H5Sclose(space);
    if (a >= 0)
        H5Aclose(a);
    H5Eclear2(H5E_DEFAULT);
    if (!ok)
        return -1;
    spacing[0] = v[2];
    spacing[1] = v[1];
    spacing[2] = v[0];
    return 1;
}

/* element_size_um (ImageJ, ilastik), else spacing; else the default 1,1,1 stays. */
static ip_status read_spacing(hid_t d, const char *path, const char *name, ip_input_desc *desc,
                              ip_error *err)
{
    static const char *const attrs[] = {"element_size_um", "spacing"};
    for (int i = 0; i < 2; i++) {
        int got = read_spacing_attr(d, attrs[i], desc->spacing);
        if (got < 0)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: dataset %s: attribute %s is not three numbers (z, y, x); pass "
                            "--spacing",
                            path, name, attrs[i]);
        if (got > 0)
            return IP_OK;
    }
    return IP_OK;
}

/* The planes a read of the dataset whose creation properties are `dcpl` brings (of `depth`;
 * `plane_bytes` each): a layer of chunks (chunk[] its chunk's shape, z first), or about
 * CONTIGUOUS_SLAB_BYTES of a contiguous dataset (chunk[0] then 0). */
static uint32_t slab_planes_of(hid_t dcpl, size_t plane_bytes, uint32_t depth, hsize_t chunk[3])
{
    uint32_t planes;
    chunk[0] = chunk[1] = chunk[2] = 0;
    if (dcpl >= 0 && H5Pget_layout(dcpl) == H5D_CHUNKED && H5Pget_chunk(dcpl, 3, chunk) == 3) {
        planes = (uint32_t)chunk[0];
    } else {
        chunk[0] = 0;
        planes =
            (uint32_t)(plane_bytes >= CONTIGUOUS_SLAB_BYTES ? 1
                                                            : CONTIGUOUS_SLAB_BYTES / plane_bytes);
    }
    H5Eclear2(H5E_DEFAULT);
    return planes == 0 || planes > depth ? depth : planes;
}

static ip_status describe_dataset(hid_t d, const char *path, const char *name,
                                  const ip_input_overrides *overrides, ip_input_desc *desc,
                                  ip_text_found *found, ip_error *err)
{
    hsize_t dims[3];
    char type[40];
    int kind, rank = dataset_shape(d, dims, type, sizeof type, &kind);
    if (rank != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: dataset %s has %d dimensions, not 3", path, name,
                        rank);
    if (kind < 0)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: dataset %s holds %s (read: uint8, int8, uint16, int16, uint32, int32, "
                        "float32, float64)",
                        path, name, type);
    ip_status st = check_filters(d, path, name, err);
    if (st == IP_OK && !(overrides && overrides->has_spacing))
        st = read_spacing(d, path, name, desc, err);
    if (st != IP_OK)
        return st;
    for (int axis = 0; axis < 3; axis++)
        found->dims[axis] = dims[2 - axis];
    found->has_dims = 1;
    found->has_type = 1;
    desc->type = kind_stored[kind];
    desc->big_endian = !ip__host_little_endian();
    desc->encoding = IP_ENCODING_HDF5;
    snprintf(desc->dataset, sizeof desc->dataset, "%s", name);
    /* the reader's slab, and as much again for a layer of chunks as stored (gzip: inflated on
     * the pool from there), in the bricker's plan (ip_input_desc.reader_bytes) */
    size_t plane_bytes = (size_t)dims[1] * dims[2] * kind_sizes[kind];
    hsize_t chunk[3];
    hid_t dcpl = H5Dget_create_plist(d);
    uint64_t planes = slab_planes_of(dcpl, plane_bytes, (uint32_t)dims[0], chunk);
    if (dcpl >= 0)
        H5Pclose(dcpl);
    desc->reader_bytes = planes * plane_bytes * (chunk[0] ? 2 : 1);
    return IP_OK;
}

static ip_status describe_locked(const char *path, const ip_input_overrides *overrides,
                                 ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    hid_t file;
    char name[IP_DATASET_MAX], why[256];
    ip_status st = open_file(path, &file, err);
    if (st != IP_OK)
        return st;
    st = pick_dataset(file, path, overrides ? overrides->dataset : NULL, name, err);
    if (st == IP_OK) {
        hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
        if (d < 0)
            st = ip__fail(err, IP_ERR_INPUT, "%s: dataset %s: cannot open (%s)", path, name,
                          hdf5_reason(why));
        else {
            st = describe_dataset(d, path, name, overrides, desc, found, err);
            H5Dclose(d);
        }
    }
    H5Fclose(file);
    H5Eclear2(H5E_DEFAULT);
    return st;
}

ip_status ip__hdf5_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    if (overrides && (overrides->has_dims || overrides->has_type || overrides->has_endian))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: an HDF5 file says its dims, type and byte order: --dims, --type and "
                        "--endian do not apply",
                        path);
    hdf5_enter();
    ip_status st = describe_locked(path, overrides, desc, found, err);
    hdf5_leave();
    return st;
}

/* ---- the plane source ---- */

typedef struct hdf5_source {
    const ip_input_desc *desc;
    hid_t file, dset;
    sample_kind kind;
    uint32_t slab_planes;        /* planes a read brings: a layer of chunks, or ~16 MiB */
    uint32_t slab_z, slab_count; /* the planes in buf */
    size_t plane_samples;
    unsigned char *buf; /* slab_planes planes as the file's type (native byte order) */
    /* gzip chunks (deflate, after shuffle or not, in the host's byte order): read as stored
     * under the lock, inflated here on the pool's threads; else libhdf5 decodes them */
    int gzip;
    ip__chunk_layer layer;
    ip__pool *pool;
    unsigned char **packed;
    size_t *packed_size, *packed_capacity;
    unsigned char *scratch;
} hdf5_source;

/* Whether the dataset's chunks are gzip as chunk_inflate.c decodes them: deflate alone or
 * after shuffle, samples stored in the host's byte order. */
static int gzip_chunks(hid_t d, hid_t dcpl, sample_kind kind, int *shuffled)
{
    int n = H5Pget_nfilters(dcpl), ok = n == 1 || n == 2;
    for (int i = 0; ok && i < n; i++) {
        unsigned flags = 0;
        size_t values = 0;
        H5Z_filter_t id = H5Pget_filter2(dcpl, (unsigned)i, &flags, &values, NULL, 0, NULL, NULL);
        ok = i == n - 1 ? id == H5Z_FILTER_DEFLATE : id == H5Z_FILTER_SHUFFLE;
    }
    hid_t t = H5Dget_type(d);
    ok = ok && t >= 0 && H5Tequal(t, kind_native(kind)) > 0;
    if (t >= 0)
        H5Tclose(t);
    *shuffled = n == 2;
    H5Eclear2(H5E_DEFAULT);
    return ok;
}

/* Sets up the parallel decoding of a layer of gzip chunks: the pool, the stored chunks' and
 * the threads' buffers. Where it cannot, libhdf5 decodes them. */
static void gzip_setup(hdf5_source *s, const hsize_t chunk[3])
{
    const ip_input_desc *d = s->desc;
    ip__chunk_layer *l = &s->layer;
    l->sample = kind_sizes[s->kind];
    for (int axis = 0; axis < 3; axis++)
        l->chunk[axis] = chunk[axis];
    l->rows = d->dims[1];
    l->columns = d->dims[0];
    l->chunks_y = (uint32_t)((l->rows + chunk[1] - 1) / chunk[1]);
    l->chunks_x = (uint32_t)((l->columns + chunk[2] - 1) / chunk[2]);
    size_t count = (size_t)l->chunks_y * l->chunks_x;
    if (ip__pool_create(ip_thread_count(0), &s->pool, NULL) != IP_OK)
        return;
    s->packed = calloc(count, sizeof *s->packed);
    s->packed_size = calloc(count, sizeof *s->packed_size);
    s->packed_capacity = calloc(count, sizeof *s->packed_capacity);
    s->scratch = malloc(ip__chunk_layer_scratch(l, ip__pool_threads(s->pool)));
    l->packed = s->packed;
    l->packed_size = s->packed_size;
    s->gzip = s->packed && s->packed_size && s->packed_capacity && s->scratch;
}

static void gzip_free(hdf5_source *s)
{
    size_t count = (size_t)s->layer.chunks_y * s->layer.chunks_x;
    for (size_t i = 0; s->packed && i < count; i++)
        free(s->packed[i]);
    free(s->packed);
    free(s->packed_size);
    free(s->packed_capacity);
    free(s->scratch);
    ip__pool_destroy(s->pool);
}

/* Checks that the dataset is still what the desc says and sizes the slab. */
static ip_status source_shape(hdf5_source *s, ip_error *err)
{
    const ip_input_desc *d = s->desc;
    hsize_t dims[3];
    char type[40];
    int kind, rank = dataset_shape(s->dset, dims, type, sizeof type, &kind);
    if (rank != 3 || kind < 0 || kind_stored[kind] != d->type || dims[2] != d->dims[0] ||
        dims[1] != d->dims[1] || dims[0] != d->dims[2])
        return ip__fail(err, IP_ERR_INPUT, "%s: dataset %s changed since it was described", d->path,
                        d->dataset);
    s->kind = (sample_kind)kind;
    s->plane_samples = (size_t)d->dims[0] * d->dims[1];
    size_t plane_bytes = s->plane_samples * kind_sizes[kind];
    hid_t dcpl = H5Dget_create_plist(s->dset);
    int shuffled = 0;
    hsize_t chunk[3];
    s->slab_planes = slab_planes_of(dcpl, plane_bytes, d->dims[2], chunk);
    if (chunk[0] && gzip_chunks(s->dset, dcpl, s->kind, &shuffled)) {
        s->layer.shuffled = shuffled;
        gzip_setup(s, chunk);
    }
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (plane_bytes > SIZE_MAX / s->slab_planes || !(s->buf = malloc(plane_bytes * s->slab_planes)))
        return ip__fail(err, IP_ERR_NOMEM, "%s: dataset %s: out of memory for %u planes", d->path,
                        d->dataset, s->slab_planes);
    return IP_OK;
}

static ip_status source_open_locked(hdf5_source *s, ip_error *err)
{
    char why[256];
    ip_status st = open_file(s->desc->path, &s->file, err);
    if (st != IP_OK)
        return st;
    /* no chunk cache: every chunk is read once, whole, straight into the slab */
    hid_t dapl = H5Pcreate(H5P_DATASET_ACCESS);
    if (dapl >= 0)
        H5Pset_chunk_cache(dapl, 0, 0, 1.0);
    s->dset = H5Dopen2(s->file, s->desc->dataset, dapl >= 0 ? dapl : H5P_DEFAULT);
    if (dapl >= 0)
        H5Pclose(dapl);
    if (s->dset < 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: dataset %s: cannot open (%s)", s->desc->path,
                        s->desc->dataset, hdf5_reason(why));
    return source_shape(s, err);
}

static void source_close(void *state)
{
    hdf5_source *s = state;
    if (!s)
        return;
    hdf5_enter();
    if (s->dset >= 0)
        H5Dclose(s->dset);
    if (s->file >= 0)
        H5Fclose(s->file);
    H5Eclear2(H5E_DEFAULT);
    hdf5_leave();
    gzip_free(s);
    free(s->buf);
    free(s);
}

static ip_status source_open(const ip_input_desc *desc, void **state, ip_error *err)
{
    hdf5_source *s = calloc(1, sizeof *s);
    *state = s;
    if (!s)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", desc->path);
    s->desc = desc;
    s->file = s->dset = -1;
    hdf5_enter();
    ip_status st = source_open_locked(s, err);
    hdf5_leave();
    return st;
}

/* Reads the stored bytes of the layer of chunks at plane z0 (under the lock). 0, or -1 when a
 * chunk is not there (the fill value) or was stored unfiltered: libhdf5 then reads the slab. */
static int read_stored_chunks(hdf5_source *s, uint32_t z0)
{
    const ip__chunk_layer *l = &s->layer;
    size_t count = (size_t)l->chunks_y * l->chunks_x;
    int ok = 1;
    for (size_t i = 0; ok && i < count; i++) {
        hsize_t offset[3] = {z0, (i / l->chunks_x) * l->chunk[1], (i % l->chunks_x) * l->chunk[2]};
        hsize_t bytes = 0;
        uint32_t mask = 0;
        ok = H5Dget_chunk_storage_size(s->dset, offset, &bytes) >= 0 && bytes > 0;
        if (ok && bytes > s->packed_capacity[i]) {
            unsigned char *grown = realloc(s->packed[i], (size_t)bytes);
            ok = grown != NULL;
            if (ok) {
                s->packed[i] = grown;
                s->packed_capacity[i] = (size_t)bytes;
            }
        }
        ok = ok && H5Dread_chunk(s->dset, H5P_DEFAULT, offset, &mask, s->packed[i]) >= 0 &&
             mask == 0;
        s->packed_size[i] = (size_t)bytes;
    }
    H5Eclear2(H5E_DEFAULT);
    return ok ? 0 : -1;
}

/* The layer of gzip chunks at plane z0 inflated on the pool's threads; 1 when libhdf5 must
 * read it instead. */
static int read_slab_gzip(hdf5_source *s, uint32_t z0, uint32_t count, ip_status *st, ip_error *err)
{
    hdf5_enter();
    int stored = read_stored_chunks(s, z0);
    hdf5_leave();
    if (stored != 0)
        return 1;
    s->layer.planes = count;
    s->layer.slab = s->buf;
    uint32_t bad = 0;
    int z = ip__chunk_layer_inflate(&s->layer, s->pool, s->scratch, &bad);
    *st = IP_OK;
    if (z != 0)
        *st =
            ip__fail(err, IP_ERR_INPUT,
                     "%s: dataset %s: the gzip chunk at (z,y,x) = (%u,%llu,%llu) does not inflate "
                     "(zlib error %d)",
                     s->desc->path, s->desc->dataset, z0,
                     (unsigned long long)((bad / s->layer.chunks_x) * s->layer.chunk[1]),
                     (unsigned long long)((bad % s->layer.chunks_x) * s->layer.chunk[2]), z);
    s->slab_z = z0;
    s->slab_count = *st == IP_OK ? count : 0;
    return 0;
}

/* Reads planes [z0, z0 + count) into buf: a hyperslab of whole z-rows of chunks. */
static ip_status read_slab(hdf5_source *s, uint32_t z0, uint32_t count, ip_error *err)
{
    ip_status gzip_st;
    if (s->gzip && read_slab_gzip(s, z0, count, &gzip_st, err) == 0)
        return gzip_st;
    const ip_input_desc *d = s->desc;
    hsize_t start[3] = {z0, 0, 0}, size[3] = {count, d->dims[1], d->dims[0]};
    char why[256];
    hdf5_enter();
    hid_t file_space = H5Dget_space(s->dset), memory = H5Screate_simple(3, size, NULL);
    herr_t ok = file_space >= 0 && memory >= 0
                    ? H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, NULL, size, NULL)
                    : -1;
    if (ok >= 0)
        ok = H5Dread(s->dset, kind_native(s->kind), memory, file_space, H5P_DEFAULT, s->buf);
    ip_status st = IP_OK;
    if (ok < 0) /* the reason first: the next call into libhdf5 clears it */
        st = ip__fail(err, IP_ERR_INPUT, "%s: dataset %s: cannot read planes %u to %u (%s)",
                      d->path, d->dataset, z0, z0 + count - 1, hdf5_reason(why));
    if (memory >= 0)
        H5Sclose(memory);
    if (file_space >= 0)
        H5Sclose(file_space);
    hdf5_leave();
    s->slab_z = z0;
    s->slab_count = st == IP_OK ? count : 0;
    return st;
}

/* A sample float32 cannot take as it is: named, with (x,y,z). */
static ip_status refuse_sample(const hdf5_source *s, size_t i, uint32_t z, const char *value,
                               const char *why, ip_error *err)
{
    const ip_input_desc *d = s->desc;
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: dataset %s: %s sample at (x,y,z) = (%u,%u,%u) is %s, %s", d->path,
                    d->dataset, kind_names[s->kind], (unsigned)(i % d->dims[0]),
                    (unsigned)(i / d->dims[0]), z, value, why);
}

/* Plane z of the slab, converted from the file's type to the desc's, into dst. */
static ip_status convert_plane(const hdf5_source *s, uint32_t z, void *dst, ip_error *err)
{
    const unsigned char *src =
        s->buf + (size_t)(z - s->slab_z) * s->plane_samples * kind_sizes[s->kind];
    size_t n = s->plane_samples;
    char value[48];
    const char *inexact = "which float32 does not hold exactly (32-bit integers are kept as "
                          "float32: exact up to 2^24)";
    switch (s->kind) {
    case K_I8:
        for (size_t i = 0; i < n; i++)
            ((int16_t *)dst)[i] = ((const int8_t *)src)[i];
        return IP_OK;
    case K_I32:
    case K_U32:
        for (size_t i = 0; i < n; i++) {
            int64_t v = s->kind == K_I32 ? (int64_t)((const int32_t *)src)[i]
                                         : (int64_t)((const uint32_t *)src)[i];
            float f = (float)v;
            if ((int64_t)f != v) {
                snprintf(value, sizeof value, "%lld", (long long)v);
                return refuse_sample(s, i, z, value, inexact, err);
            }
            ((float *)dst)[i] = f;
        }
        return IP_OK;
    case K_F64:
        for (size_t i = 0; i < n; i++) {
            double v = ((const double *)src)[i];
            if (v > FLT_MAX || v < -FLT_MAX) {
                snprintf(value, sizeof value, "%g", v);
                return refuse_sample(s, i, z, value, "beyond float32's range", err);
            }
            ((float *)dst)[i] = (float)v; /* NaN stays NaN: the reader refuses it */
        }
        return IP_OK;
    default: break;
    }
    memcpy(dst, src, n * kind_sizes[s->kind]);
    return IP_OK;
}

static ip_status source_read_plane(void *state, uint32_t z, void *dst, ip_error *err)
{
    hdf5_source *s = state;
    if (z < s->slab_z || z >= s->slab_z + s->slab_count) {
        uint32_t z0 = z - z % s->slab_planes, count = s->slab_planes;
        if (count > s->desc->dims[2] - z0)
            count = s->desc->dims[2] - z0;
        ip_status st = read_slab(s, z0, count, err);
        if (st != IP_OK)
            return st;
    }
    return convert_plane(s, z, dst, err);
}

#else /* !IP_HAVE_HDF5 */

#define NO_HDF5                                                                                   \
    "an HDF5 file, but this isoprop was built without HDF5 input (install libhdf5-dev and build " \
    "with -DIP_HDF5=ON)"

ip_status ip__hdf5_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    (void)overrides, (void)desc, (void)found;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: " NO_HDF5, path);
}

static ip_status source_open(const ip_input_desc *desc, void **state, ip_error *err)
{
    *state = NULL;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: " NO_HDF5, desc->path);
}

static ip_status source_read_plane(void *state, uint32_t z, void *dst, ip_error *err)
{
    (void)state, (void)z, (void)dst;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "HDF5: " NO_HDF5);
}

static void source_close(void *state)
{
    (void)state;
}

#endif

const ip__plane_source ip__hdf5_source = {source_open, source_read_plane, source_close};
