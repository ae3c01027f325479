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
#ifndef IP_PATH_MAX
#define IP_PATH_MAX 4096
#endif

/*! ip_type_size() : bytes per sample of `type` (1, 2 or 4); 0 for an unknown type. */
size_t ip_type_size(ip_type type);

/*! ip_type_name() : the canonical name ("uint8", "uint16", "int16", "float32"), or "unknown". */
const char *ip_type_name(ip_type type);

/*! ip_type_parse() : parses a type name; accepts the canonical names and the common aliases
 *  (uchar, ushort, short, float, MET_UCHAR, ...).
 *  @return IP_OK and *out set, or IP_ERR_ARGUMENT for an unknown name (*out untouched). */
ip_status ip_type_parse(const char *name, ip_type *out);

/*! ip_sample_get() : sample `index` of a native-endian array of `type`, as a float; 0 for an
 *  unknown type. Exact for every supported type (uint8/uint16/int16 fit a float's 24-bit
 *  mantissa). An inline definition, so that callers that read sample by sample pay no call;
 *  src/volume.c holds the external one. (Loops over many samples of one type do better
 *  still to switch on the type once, outside the loop.) */
inline float ip_sample_get(const void *samples, ip_type type, size_t index)
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
ip_status ip_dims_parse(const char *text, uint32_t dims[3]);

#ifdef __cplusplus
}
#endif
#endif
