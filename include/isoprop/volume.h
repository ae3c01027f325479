/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: sample types and volume geometry shared by every layer.
 *
 * A volume is a grid of dims[0] x dims[1] x dims[2] samples, x fastest, then y, then z.
 * Cells are the unit cubes between 8 neighbouring samples, so a volume has (dims - 1) cells
 * along each axis. Spacing is the world-space distance between samples along each axis.
 */
#ifndef ISOPROP_VOLUME_H
#define ISOPROP_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ip_type {
    IP_UINT8 = 0,
    IP_UINT16 = 1,
    IP_INT16 = 2,
    IP_FLOAT32 = 3
} ip_type;

#define IP_TYPE_COUNT 4

/* Longest path the library stores, in bytes (including the terminating NUL). */
#define IP_PATH_MAX 4096

/*! ip_type_size() : bytes per sample of `type` (1, 2 or 4); 0 for an unknown type. */
IP_API size_t ip_type_size(ip_type type);

/*! ip_type_holds() : 1 when a sample of `type` can hold `value` exactly (an integer within
 *  the type's range; any finite value for float32), else 0. */
IP_API int ip_type_holds(ip_type type, float value);

/*! ip_type_name() : the canonical name ("uint8", "uint16", "int16", "float32"), or "unknown". */
IP_API const char *ip_type_name(ip_type type);

/*! ip_type_parse() : parses a type name; accepts the canonical names and the common aliases
 *  (uchar, ushort, short, float, MET_UCHAR, ...).
 *  @return IP_OK and *out set, or IP_ERR_ARGUMENT for an unknown name (*out untouched). */
IP_API ip_status ip_type_parse(const char *name, ip_type *out);

/*! ip_sample_get() : sample `index` of a native-endian array of `type`, as a float; 0 for an
 *  unknown type. Exact for every supported type (uint8/uint16/int16 fit a float's 24-bit
 *  mantissa). An inline definition, so that callers that read sample by sample pay no call;
 *  src/common/volume.c holds the external one. (Loops over many samples of one type do better
 *  still to switch on the type once, outside the loop.) */
IP_API inline float ip_sample_get(const void *samples, ip_type type, size_t index)
{
    switch (type) {
    case IP_UINT8: return (float)((const uint8_t *)samples)[index];
    case IP_UINT16: return (float)((const uint16_t *)samples)[index];
    case IP_INT16: return (float)((const int16_t *)samples)[index];
    case IP_FLOAT32: return ((const float *)samples)[index];
    }
    return 0.0f;
}

/*! ip_dims_parse() : parses "XxYxZ" (e.g. "512x512x234") into dims; each must be in [1, 2^31).
 *  @return IP_OK, or IP_ERR_ARGUMENT when the text is not three positive integers. */
IP_API ip_status ip_dims_parse(const char *text, uint32_t dims[3]);

/* The spacings (world units between samples) the whole pipeline renders correctly: camera
 * framing, seeding, propagation, level of detail, float32 vertex positions and normals, the
 * software rasterizer and OpenGL. Measured limits and the safety margins are in
 * docs/format.md (the header's spacing field). Every component must lie in
 * [IP_SPACING_MIN, IP_SPACING_MAX], and the largest may be at most IP_SPACING_RATIO_MAX times
 * the smallest. */
#define IP_SPACING_MIN 1e-9
#define IP_SPACING_MAX 1e6
#define IP_SPACING_RATIO_MAX 1e3

/*! ip_spacing_check() : checks that `spacing` (world units along x, y, z) is within the bounds
 *  above. `name` (a file name, may be NULL) starts the message. Reentrant.
 *  @return IP_OK, or IP_ERR_UNSUPPORTED with a one-line message giving the accepted range
 *  (and suggesting another unit, or resampling for too large a ratio). */
IP_API ip_status ip_spacing_check(const double spacing[3], const char *name, ip_error *err);

/* Bytes of a rescale's unit name, its terminating NUL included. */
#define IP_RESCALE_UNIT_MAX 16

/* What a volume's stored sample values stand for: value = stored x slope + intercept, in
 * `unit` (a DICOM CT's Hounsfield units: slope 1, intercept -1024, "HU"). Samples are always
 * kept as stored; isovalues given in the file's units are turned into stored values by
 * ip_rescale_to_stored(). A volume without one has present 0, slope 1, intercept 0, unit "". */
typedef struct ip_rescale {
    int present;                    /* 1 when the volume has a rescale */
    double slope;                   /* finite, not 0; a negative slope reverses the order */
    double intercept;               /* finite */
    char unit[IP_RESCALE_UNIT_MAX]; /* printable ASCII, NUL-terminated; "" when unknown */
} ip_rescale;

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same. */
#ifdef IP_EXPERIMENTAL

/*! ip_rescale_identity() : *r = no rescale (present 0, slope 1, intercept 0, unit ""). */
IP_API void ip_rescale_identity(ip_rescale *r);

/*! ip_rescale_to_stored() : the stored sample value that `value`, in r's units, stands for:
 *  (value - intercept) / slope, in double; `value` itself when r is NULL or has no rescale.
 *  The one conversion every program and the Python module use, so that an isovalue in the
 *  file's units and the stored value it stands for extract the same surface. Exact where the
 *  result is a whole number below 2^53 and slope is 1 (any integer intercept), or a power of
 *  two. With a negative slope, values above `value` are stored values below the result.
 *  Reentrant. */
IP_API double ip_rescale_to_stored(const ip_rescale *r, double value);

/*! ip_rescale_to_value() : what stored sample value `stored` stands for, in r's units:
 *  stored x slope + intercept; `stored` itself when r is NULL or has no rescale. Reentrant. */
IP_API double ip_rescale_to_value(const ip_rescale *r, double stored);

/*! ip_rescale_check() : checks *r: slope finite and not 0, intercept finite, unit at most
 *  IP_RESCALE_UNIT_MAX - 1 printable ASCII characters (0x20 .. 0x7e), NUL-terminated. A rescale
 *  that is not present is always valid. `name` (a file name, may be NULL) starts the message.
 *  @return IP_OK, or IP_ERR_ARGUMENT with a one-line message. Reentrant. */
IP_API ip_status ip_rescale_check(const ip_rescale *r, const char *name, ip_error *err);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif
