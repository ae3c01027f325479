/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: reading input volumes (headerless raw, NRRD, MetaImage, TIFF, NIfTI, DICOM, Zarr
 * and OME-Zarr) plane by plane.
 *
 * ip_input_describe() works out where the samples are and how they are laid out, from a file
 * name of the form NAME_XxYxZ_TYPE.raw, from a NRRD header (.nrrd attached, .nhdr detached;
 * raw or gzip encoding), a MetaImage header (.mhd with its data file), a TIFF file or a folder
 * of TIFF files, a NIfTI-1/2 file (.nii, .nii.gz) or a folder holding a DICOM series, and from
 * explicit overrides. A reader then streams z-planes in order with bounded memory.
 */
#ifndef ISOPROP_INPUT_H
#define ISOPROP_INPUT_H

#include <stdint.h>

#include "isoprop/orientation.h"
#include "isoprop/status.h"
#include "isoprop/volume.h"

#ifdef __cplusplus
extern "C" {
#endif

/* How the samples are stored. */
typedef enum ip_encoding {
    IP_ENCODING_RAW = 0,      /* plain samples from data_offset on */
    IP_ENCODING_GZIP = 1,     /* a gzip (or zlib) stream from data_offset on */
    IP_ENCODING_TIFF = 2,     /* one TIFF page a plane: a multi-page file or a folder of files */
    IP_ENCODING_DICOM = 3,    /* one DICOM file a plane: a folder holding one series */
    IP_ENCODING_CALLBACK = 4, /* the caller's function fills the planes: plane_source and
                                 plane_user (ip_input_desc_from_planes(), experimental) */
    IP_ENCODING_HDF5 = 5,     /* one 3-D dataset of an HDF5 file (`dataset`), read a layer of
                                 chunks at a time through libhdf5 in the input component */
    IP_ENCODING_ZARR = 6      /* chunks of a Zarr v2 or v3 array (an OME-Zarr image's scale):
                                 data_path is the array's folder */
} ip_encoding;

/* Bytes of ip_input_desc.dataset: an HDF5 dataset's path is at most 95 characters. */
#define IP_DATASET_MAX 96

/* A caller's source of z-planes (IP_ENCODING_CALLBACK): fills `dst` with the `count` planes
 * from plane `z` on, dims[0] x dims[1] samples each of the desc's type, x fastest, in the
 * host's byte order. The reader calls it for z = 0, 1, ... in order, each plane once, from
 * one thread at a time (not always the same one: the bricker may read on a helper thread).
 * Returns IP_OK, or an error status that ends the reading; it may then put a message in
 * *err (the reader names the source when it leaves *err empty). */
typedef ip_status (*ip_plane_source_fn)(void *user, uint32_t z, uint32_t count, void *dst,
                                        ip_error *err);

/* Where a volume's samples are and how to read them. */
typedef struct ip_input_desc {
    char path[IP_PATH_MAX];      /* the file the user named (header or raw) */
    char data_path[IP_PATH_MAX]; /* the file that holds the samples; "-" (with path "-"):
                                    standard input, raw samples read once in order */
    uint64_t data_offset;        /* byte offset of the first sample in data_path */
    uint32_t dims[3];            /* samples along x, y, z; each >= 2 */
    ip_type type;
    int big_endian;    /* 1 when the stored samples are big-endian */
    double spacing[3]; /* world units between samples; default 1,1,1 */
    ip_encoding encoding;
    uint64_t stream_skip; /* gzip: bytes of the inflated stream before the first sample (a
                             header inside the stream, as in .nii.gz); 0 otherwise */
    int has_rescale;      /* 1 when the file says its values stand for stored x rescale_slope
                             + rescale_intercept, in rescale_unit (NIfTI scl_slope/scl_inter,
                             DICOM Rescale Slope/Intercept/Type); the bricker keeps it in the
                             brick file (ip_layout.rescale); samples keep their stored values */
    double rescale_slope;
    double rescale_intercept;
    ip_orientation orientation; /* origin, axis directions and space in the file's physical
                                   space (NRRD space origin/directions/space, MetaImage
                                   Offset/TransformMatrix/AnatomicalOrientation, NIfTI sform or
                                   qform, DICOM image position/orientation); identity when the
                                   file says nothing or its axes are not orthonormal */
    /* A DICOM folder (docs/dicom.md); zero for other inputs. */
    char series_uid[72];      /* the Series Instance UID read (at most 64 characters) */
    uint32_t series_count;    /* series in the folder (with its subfolders) */
    uint32_t skipped_objects; /* DICOM objects of the folder that are not images (a SOP class
                                 of a directory, a report, a presentation state, ...): skipped */
    uint32_t source_slices;   /* the series' files (slices) */
    uint32_t resampled;       /* IP_RESAMPLED_* bits: why the slices were resampled onto the
                                 regular grid dims x spacing (interpolated samples); 0: the
                                 samples are the stored ones, one slice a plane */
    double tilt_degrees;      /* the angle between the slices' stacking direction and their
                                 normal (a gantry tilt); 0 when they stack along the normal */
    char rescale_unit[IP_RESCALE_UNIT_MAX]; /* with has_rescale: the values' unit, "" when the
                                               file names none ("HU" for a DICOM CT) */
    /* IP_ENCODING_CALLBACK only (ip_input_desc_from_planes()); NULL otherwise. */
    ip_plane_source_fn plane_source; /* fills the planes */
    void *plane_user;                /* passed to plane_source, not owned */
    char dataset[IP_DATASET_MAX];    /* IP_ENCODING_HDF5: the dataset's path in the file ("/a/b");
                                     "" otherwise */
    /* A Zarr array or OME-Zarr image (docs/input.md, "Zarr and OME-Zarr"); zero for other
     * inputs. */
    uint64_t reader_bytes; /* memory the reader holds besides the planes it hands out (a
                              Zarr row of chunks), which the bricker's plan counts */
    uint32_t zarr_time;    /* OME-Zarr: the time point read (0 without a t axis) */
    uint16_t zarr_channel; /* OME-Zarr: the channel read (0 without a c axis) */
    uint8_t zarr_scale;    /* OME-Zarr: the scale read (0 the finest) */
    uint8_t zarr_scales;   /* OME-Zarr: the image's scales (at most 255); 0: not OME-Zarr */
    char space_unit[8];    /* OME-Zarr: the unit of spacing and origin, as a symbol ("um" for
                              micrometer, "mm", "nm", ...), "" when the file names none */
    uint64_t reserved[1];  /* zero: room for later fields at the same size (status.h) */
} ip_input_desc;

/* ip_input_desc.resampled: the slices of a DICOM series were resampled onto a regular grid
 * because they are sheared (a gantry tilt) or unevenly spaced along their normal. */
#define IP_RESAMPLED_TILT 1u
#define IP_RESAMPLED_UNEVEN 2u

/* How a DICOM series whose slices do not lie on a regular grid is read
 * (ip_input_overrides.tilt and .uneven; docs/dicom.md). */
typedef enum ip_regrid {
    IP_REGRID_DEFAULT = 0,  /* a tilt is resampled, uneven spacing refused */
    IP_REGRID_RESAMPLE = 1, /* resampled onto a regular grid in physical space */
    IP_REGRID_REFUSE = 2    /* refused (IP_ERR_INPUT) */
} ip_regrid;

/* Values given on the command line; each applies only where its has_ flag is set, and wins
 * over the file name and over any header. A header field that an override replaces is not
 * read at all (has_dims covers NRRD dimension/sizes and MetaImage NDims/DimSize, has_spacing
 * covers spacings/space directions and ElementSpacing/ElementSize), so an override can stand
 * in for a header value this library cannot use. Where the data start, their encoding and
 * their data file always come from the header. */
typedef struct ip_input_overrides {
    uint32_t size; /* bytes of the struct as the caller compiled it (IP_SIZED); see status.h */
    int has_dims;
    uint32_t dims[3];
    int has_type;
    ip_type type;
    int has_endian;
    int big_endian;
    int has_spacing;
    double spacing[3];
    /* A DICOM folder (after 0.2.0; zero keeps the defaults). Read only when `size` covers
     * them (IP_SIZED(ip_input_overrides)): a size of 0 stands for 0.2.0's layout, which has
     * none, so they are then ignored. */
    const char *series; /* the Series Instance UID, or a prefix of one only, of the series to
                           read from a folder holding several; NULL: the folder must hold one.
                           Not copied: valid during ip_input_describe() */
    ip_regrid tilt;     /* slices sheared by a gantry tilt; default: resampled */
    ip_regrid uneven;   /* slices unevenly spaced (a slice missing included); default: refused */
    /* An HDF5 file (after 0.2.0, read only when `size` covers it, as `series`). */
    const char *dataset; /* the path of the 3-D dataset to read ("/volume"); NULL: the file must
                            hold exactly one. Refused for other inputs. Not copied */
    /* An OME-Zarr image (after 0.2.0; read only when `size` covers them): the scale (0, the
     * finest, by default), and the time point and channel where the image has t or c axes
     * longer than 1 (required there). Refused (IP_ERR_ARGUMENT) for any other input. */
    int has_scale;
    uint32_t scale;
    int has_time;
    uint32_t time;
    int has_channel;
    uint32_t channel;
} ip_input_overrides;

/*! ip_input_describe() : fills *out for the volume at `path`.
 *  `overrides` may be NULL. The extension picks the format: .nrrd/.nhdr NRRD, .mhd/.mha
 *  MetaImage, .tif/.tiff TIFF, .nii/.nii.gz NIfTI, .h5/.hdf5/.he5 (or a file that starts with
 *  the HDF5 signature) HDF5 (docs/input.md; needs the input component built with HDF5);
 *  "-" standard input (raw samples: the overrides must give dims and type); a folder
 *  holding .zarray, .zattrs, .zgroup or zarr.json is a Zarr array or OME-Zarr image
 *  (docs/input.md), any other folder a DICOM series or numbered TIFF files (told apart by
 *  the first file's content); anything else is headerless raw (little-endian, spacing
 *  1,1,1, dims and type from a base name NAME_XxYxZ_TYPE.raw or from the overrides).
 *  Checks everything that can be checked before reading samples: a dimension under 2 (or
 *  at or above 2^31), an unknown
 *  type, an unreadable or malformed header, a header or data file that is not a regular file
 *  (a FIFO or a device is refused at once, never waited on), a missing data file, a size past
 *  2^63 bytes, (raw encoding) a data size that does not equal dims x type size, and a spacing
 *  outside the bounds of ip_spacing_check(); the length of gzip data is checked by the
 *  reader. Reentrant; *out is untouched on failure.
 *  @return IP_OK, or IP_ERR_INPUT / IP_ERR_IO with err->message naming the file and the
 *  problem in one line; IP_ERR_UNSUPPORTED for a spacing outside the renderable range, or a
 *  valid TIFF or NIfTI file this library does not read (a sample type, a compression, 4D
 *  images, .hdr/.img pairs: docs/input.md);
 *  IP_ERR_ARGUMENT for a NULL or over-long path, a NULL out, an override type that is not
 *  an ip_type, or an OME-Zarr choice (has_scale, has_time, has_channel) for another input
 *  or out of the image's range; IP_ERR_UNSUPPORTED also for a Zarr folder where the input
 *  component was built without Zarr; IP_ERR_NOMEM when an allocation fails. */
IP_API ip_status ip_input_describe(const char *path, const ip_input_overrides *overrides,
                                   ip_input_desc *out, ip_error *err);

/* A sequential plane reader. Not thread-safe; one owner at a time. */
typedef struct ip_input_reader ip_input_reader;

/*! ip_input_open() : opens a reader positioned at plane z = 0. *out is owned by the caller
 *  and released with ip_input_close(). Gzip streams use a fixed 256 KiB input buffer and
 *  inflate straight into the caller's planes. @return IP_OK, IP_ERR_IO or IP_ERR_NOMEM;
 *  IP_ERR_INPUT when the data file is no longer a regular file, when gzip data end within
 *  the stream_skip bytes before the samples, or when a TIFF file no longer reads; IP_ERR_ARGUMENT for NULL
 *  arguments or a desc without type and dims. */
IP_API ip_status ip_input_open(const ip_input_desc *desc, ip_input_reader **out, ip_error *err);

/*! ip_input_read_planes() : reads the next `count` z-planes into `dst`, which must hold
 *  count * dims[0] * dims[1] samples; samples arrive in the host's byte order.
 *  A gzip stream that ends early or is longer than the dims is reported as IP_ERR_INPUT (the
 *  end is checked by the call that reads the last plane); float32 samples that are NaN or
 *  infinite are reported as IP_ERR_INPUT naming the sample as (x,y,z). After any error the
 *  reader only repeats it. count 0 reads nothing.
 *  @return IP_OK, IP_ERR_IO or IP_ERR_INPUT; IP_ERR_NOMEM when zlib runs out of memory;
 *  IP_ERR_ARGUMENT for reading past the last plane
 *  or a NULL reader or dst. */
IP_API ip_status ip_input_read_planes(ip_input_reader *reader, void *dst, uint32_t count,
                                      ip_error *err);

/*! ip_input_close() : releases the reader (NULL is allowed). */
IP_API void ip_input_close(ip_input_reader *reader);

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same. */
#ifdef IP_EXPERIMENTAL

/* One series of a DICOM folder, as ip_dicom_list_series() finds it. */
typedef struct ip_dicom_series_info {
    char uid[72];         /* Series Instance UID (0020,000E), at most 64 characters */
    char description[72]; /* Series Description (0008,103E), "" when none */
    char modality[24];    /* Modality (0008,0060), "" when none */
    uint32_t slices;      /* its files */
    uint32_t dims[3];     /* the volume it reads as: columns, rows, planes (the slices, or the
                             planes of the grid it is resampled onto); 0 when it cannot be read */
    ip_type type;
    double spacing[3];   /* x, y from Pixel Spacing, z between planes; mm; 0 when unknown */
    double tilt_degrees; /* as ip_input_desc.tilt_degrees */
    uint32_t resampled;  /* IP_RESAMPLED_* bits: what reading it with IP_REGRID_RESAMPLE
                             resamples */
    char problem[512];   /* "" or the one line that says why it cannot be read as it is (under
                             the default ip_regrid choices) */
} ip_dicom_series_info;

/*! ip_dicom_list_series() : the series of the DICOM folder `folder` (its subfolders included),
 *  in the order of their first files by name, into *out (count entries, owned by the caller, released with
 *  free()); *skipped (may be NULL) receives the number of DICOM objects that are not images.
 *  A series that cannot be read is listed with its problem; a file that is not DICOM, or
 *  whose series cannot be told, fails the call.
 *  @return IP_OK, or IP_ERR_INPUT / IP_ERR_IO naming the folder or file, IP_ERR_UNSUPPORTED
 *  when the input component cannot be loaded, IP_ERR_NOMEM. */
IP_API ip_status ip_dicom_list_series(const char *folder, ip_dicom_series_info **out,
                                      uint32_t *count, uint32_t *skipped, ip_error *err);

/*! ip_input_desc_from_planes() : fills *desc for a volume whose samples the caller's function
 *  `fn` gives plane by plane (IP_ENCODING_CALLBACK; `user` is passed to it, not owned): dims
 *  (x, y, z, each 2 .. 2^31 - 1) samples of `type`, `spacing` (NULL: 1,1,1), no rescale, an
 *  identity orientation. `name` (e.g. "array") stands for the volume in messages, as a path
 *  does. A reader (ip_input_open()) or the bricker (ip_bricker_run(), which then checks no
 *  output against an input file) reads it like any other desc; float32 NaN and infinities are
 *  refused as for files. @return IP_OK; IP_ERR_ARGUMENT for a NULL desc, name or fn, a name
 *  of IP_PATH_MAX bytes or more, dims out of range or an unknown type (*desc untouched). */
IP_API ip_status ip_input_desc_from_planes(ip_input_desc *desc, const char *name,
                                           const uint32_t dims[3], ip_type type,
                                           const double spacing[3], ip_plane_source_fn fn,
                                           void *user, ip_error *err);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif
