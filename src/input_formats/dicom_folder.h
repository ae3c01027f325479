/* SPDX-License-Identifier: BSD-3-Clause */
/* DICOM input, internal: a folder of DICOM files (its subfolders included) read file by file
 * into the slices of its series (dicom_folder.c), and the geometry of one series: its order
 * along the slice normal, its steps, a gantry tilt, and the regular grid it is read on, with
 * the resampling of its slices onto that grid (dicom_grid.c). input_dicom.c describes and
 * reads through them. Not part of the public API. */
#ifndef ISOPROP_DICOM_FOLDER_H
#define ISOPROP_DICOM_FOLDER_H

#include <stdint.h>

#include "dicom_gdcm.h"
#include "isoprop/input.h"
#include "isoprop/volume.h"

/* One image file, as its header describes it. */
typedef struct dicom_slice {
    char *name;      /* its path within the folder (a/b/IM0001 in subfolders), owned by the
                        folder */
    uint32_t series; /* its series: the index in dicom_folder.series */
    uint32_t columns, rows;
    ip_type type;
    uint32_t bits_stored, high_bit; /* where the samples' bits lie in each pixel */
    int has_pixel_spacing;
    double pixel_spacing[2]; /* between rows (y), between columns (x); mm */
    double position[3], orientation[6];
    double slope, intercept;
    char unit[IP_RESCALE_UNIT_MAX]; /* of the rescaled values (input_dicom.c's rescale_unit()) */
    double along; /* position along the slice normal, mm (set by ip__dicom_grid_plan) */
} dicom_slice;

/* One series of a folder: the files that share a Series Instance UID. */
typedef struct dicom_group {
    char uid[IP_DICOM_VALUE_MAX];
    char description[IP_DICOM_VALUE_MAX];
    char modality[IP_DICOM_VALUE_MAX];
    uint64_t files;
    int failed;     /* a file of it cannot be read as a slice: */
    ip_error error; /* ... the first one's (by name) message */
} dicom_group;

/* A folder's image files, by name, and their series, in the order of their first file. */
typedef struct dicom_folder {
    const char *path;
    dicom_slice *slices;
    uint64_t count, capacity;
    dicom_group *series;
    uint32_t series_count, series_capacity;
    uint64_t skipped; /* DICOM objects that are not images */
} dicom_folder;

/*! ip__dicom_folder_scan() : lists the regular, visible files of `path` and its subfolders
 *  (not following links to folders), skips those that are not images by their SOP class, and
 *  reads the header of every other one into f. A file that is not DICOM, or that fails before
 *  its series is known, fails the scan naming it; one that fails later marks its series
 *  failed. The caller frees f with ip__dicom_folder_free() (also on failure). */
ip_status ip__dicom_folder_scan(dicom_folder *f, const char *path, ip_error *err);

void ip__dicom_folder_free(dicom_folder *f);

/*! ip__dicom_folder_pick() : the series `wanted` names (a UID, or a prefix of one only), or,
 *  `wanted` NULL, the folder's one series, into *out. IP_ERR_INPUT naming the folder when it
 *  holds no image, none or several match, or it holds several and none is wanted (the message
 *  lists them). */
ip_status ip__dicom_folder_pick(const dicom_folder *f, const char *wanted, uint32_t *out,
                                ip_error *err);

/* `text` as a message shows it: control characters as '?', cut to IP_DICOM_VALUE_MAX
 * (input_dicom.c). */
const char *ip__dicom_shown(const char *text, char out[IP_DICOM_VALUE_MAX]);

/*! ip__dicom_read_slice() : the fields of the file at `path` (its header h, read) into
 *  *slice, each checked on its own (input_dicom.c): the transfer syntax, one grey sample a
 *  pixel in one frame, the sample type and bit layout, size, pixel spacing, position,
 *  orientation, rescale. */
ip_status ip__dicom_read_slice(const char *path, const ip_dicom_header *h, dicom_slice *slice,
                               ip_error *err);

/* The slices of one series, sorted by name, then by position once planned. */
typedef struct dicom_series {
    const char *folder;
    dicom_slice *slices; /* copies: their names stay the folder's */
    uint64_t count;
} dicom_series;

/*! ip__dicom_check_alike() : the slices of s alike: size, type, bit layout, pixel spacing,
 *  orientation, rescale (one volume, one rescale); else the first unlike the first slice, named
 *  (input_dicom.c). */
ip_status ip__dicom_check_alike(const dicom_series *s, ip_error *err);

/*! ip__dicom_series_of() : the slices of series `index` of f, checked alike (size, type, bit
 *  layout, pixel spacing, orientation, rescale), into *out (freed with free(out->slices), also
 *  on failure); the series' first failing file's message when it has one. */
ip_status ip__dicom_series_of(const dicom_folder *f, uint32_t index, dicom_series *out,
                              ip_error *err);

/* The regular grid a series is read on: the slices' own (one a plane), or one it is resampled
 * onto, whose axes are the rows, the columns and the normal of its slices. */
typedef struct dicom_grid {
    uint32_t dims[3];
    double spacing[3]; /* x, y from Pixel Spacing (0 without it), z between planes; mm */
    ip_orientation orientation;
    uint32_t resampled;  /* IP_RESAMPLED_* bits; 0: the slices are the planes */
    double tilt_degrees; /* 0 when the slices stack along their normal */
    double start[2];     /* resampled: the first sample, mm along the first slice's rows and
                            columns from its position */
    double *offsets;     /* resampled: each slice's position less the first's, mm along the
                            rows and the columns (2 a slice; owned) */
} dicom_grid;

/*! ip__dicom_grid_plan() : sorts the slices of s along their normal, checks the steps (a
 *  repeated slice is refused), finds a gantry tilt and uneven steps and takes each as `tilt`
 *  and `uneven` say, and works out the grid *g (freed with ip__dicom_grid_free(), also on
 *  failure). IP_ERR_INPUT naming the folder: one slice, a repeated one, a tilt or uneven steps
 *  refused (the message names the choice that resamples them), a grid over 4 times the
 *  slices' own size. */
ip_status ip__dicom_grid_plan(dicom_series *s, ip_regrid tilt, ip_regrid uneven, dicom_grid *g,
                              ip_error *err);

void ip__dicom_grid_free(dicom_grid *g);

/* Decodes slice `index` (of the sorted series) into dst, one slice of samples; the resampler's
 * caller's. */
typedef ip_status (*dicom_decode_fn)(void *user, uint64_t index, void *dst, ip_error *err);

/* The resampling of a series' slices onto its grid, plane by plane in order, holding at most
 * two slices. */
typedef struct dicom_resampler {
    const dicom_series *s;
    const dicom_grid *g;
    unsigned char *slot[2]; /* slices held, slot_of[k] the slice in slot k (UINT64_MAX: none) */
    uint64_t slot_of[2];
    uint64_t next;     /* the first slice a later plane may need */
    double background; /* outside every slice: the lowest sample of the first */
} dicom_resampler;

ip_status ip__dicom_resampler_init(dicom_resampler *r, const dicom_series *s, const dicom_grid *g,
                                   ip_error *err);

/*! ip__dicom_resample_plane() : plane z of the grid (planes in order) into dst (dims[0] x
 *  dims[1] samples of the slices' type): each slice sampled bilinearly at the plane's points
 *  projected on it, between the two slices around the plane linearly along the normal, the
 *  result rounded to the nearest stored value; samples outside every slice take the
 *  background. Slices are decoded through `decode`. */
ip_status ip__dicom_resample_plane(dicom_resampler *r, uint32_t z, void *dst,
                                   dicom_decode_fn decode, void *user, ip_error *err);

void ip__dicom_resampler_free(dicom_resampler *r);

#endif
