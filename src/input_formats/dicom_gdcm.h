/* SPDX-License-Identifier: BSD-3-Clause */
/* Internal to the input module: the few calls into the DICOM library (GDCM, dicom_gdcm.cpp)
 * behind a C interface, so that the rest of DICOM input (listing, grouping, sorting, checks,
 * messages: input_dicom.c) is C. Nothing thrown or allocated in C++ crosses it. Not part of
 * the public API. */
#ifndef ISOPROP_DICOM_GDCM_H
#define ISOPROP_DICOM_GDCM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The header fields DICOM input reads, each kept as the text of its value ("" when the file
 * lacks it); the values of a multi-valued field are separated by '\'. */
typedef enum ip_dicom_field {
    IP_DICOM_TRANSFER_SYNTAX,      /* (0002,0010) Transfer Syntax UID */
    IP_DICOM_SERIES_UID,           /* (0020,000E) Series Instance UID */
    IP_DICOM_MODALITY,             /* (0008,0060) Modality: CT, MR, ... */
    IP_DICOM_SERIES_DESCRIPTION,   /* (0008,103E) Series Description */
    IP_DICOM_POSITION,             /* (0020,0032) Image Position (Patient): x\y\z in mm */
    IP_DICOM_ORIENTATION,          /* (0020,0037) Image Orientation (Patient): row\column */
    IP_DICOM_SAMPLES_PER_PIXEL,    /* (0028,0002) */
    IP_DICOM_PHOTOMETRIC,          /* (0028,0004) Photometric Interpretation */
    IP_DICOM_FRAMES,               /* (0028,0008) Number of Frames */
    IP_DICOM_ROWS,                 /* (0028,0010) */
    IP_DICOM_COLUMNS,              /* (0028,0011) */
    IP_DICOM_PIXEL_SPACING,        /* (0028,0030) row spacing (y) \ column spacing (x), mm */
    IP_DICOM_BITS_ALLOCATED,       /* (0028,0100) */
    IP_DICOM_BITS_STORED,          /* (0028,0101) */
    IP_DICOM_HIGH_BIT,             /* (0028,0102) */
    IP_DICOM_PIXEL_REPRESENTATION, /* (0028,0103) 0 unsigned, 1 two's complement */
    IP_DICOM_RESCALE_INTERCEPT,    /* (0028,1052) */
    IP_DICOM_RESCALE_SLOPE,        /* (0028,1053) */
    IP_DICOM_RESCALE_TYPE,         /* (0028,1054) the rescaled values' unit: HU, OD, US, ... */
    IP_DICOM_FIELD_COUNT
} ip_dicom_field;

/* Longer values than this are cut (none of the fields read is that long when well formed). */
#define IP_DICOM_VALUE_MAX 256

/* What ip__dicom_read_header() found in one file. */
typedef struct ip_dicom_header {
    char value[IP_DICOM_FIELD_COUNT][IP_DICOM_VALUE_MAX];
    int syntax_known;     /* 1 when the transfer syntax UID is one the library knows */
    int syntax_decodable; /* 1 when, besides, one of its codecs decodes that syntax */
    char syntax_name[IP_DICOM_VALUE_MAX]; /* the syntax's name when known, else "" */
} ip_dicom_header;

/*! ip__dicom_read_header() : reads the header of the DICOM Part 10 file at `path`, up to its
 *  pixel data (which are not read), into *out.
 *  @return : 0, or -1 with a short reason (no file name) in why[why_size]. Thread-safe for
 *  different files. */
int ip__dicom_read_header(const char *path, ip_dicom_header *out, char *why, size_t why_size);

/* The geometry of a decoded image. */
typedef struct ip_dicom_image {
    unsigned columns, rows;
    unsigned bits_allocated;
    unsigned samples_per_pixel;
    int is_signed;
    unsigned frames;
    unsigned long long bytes; /* the decoded image's size */
} ip_dicom_image;

/*! ip__dicom_decode() : decodes the pixel data of the DICOM file at `path` (whatever its
 *  transfer syntax, when a codec of the library decodes it) into dst, which holds `capacity`
 *  bytes, in the host's byte order; *image receives the decoded geometry. Nothing is written
 *  to dst when the decoded image is larger than `capacity`.
 *  @return : 0, or -1 with a short reason (no file name) in why[why_size]; *image is filled
 *  as far as it was known. */
int ip__dicom_decode(const char *path, void *dst, size_t capacity, ip_dicom_image *image, char *why,
                     size_t why_size);

#ifdef __cplusplus
}
#endif
#endif
