/* isoprop: synthetic and upsampled volumes for tests, demos and benchmarks.
 *
 * Every generator is a pure function of (parameters, sample position), so a volume of any size
 * is written plane by plane with bounded memory, and the same parameters always give the same
 * bytes. Output files are named NAME_XxYxZ_TYPE.raw so that isobrick needs no flags.
 */
#ifndef ISOPROP_GENERATE_H
#define ISOPROP_GENERATE_H

#include <stdint.h>

#include "isoprop/input.h"
#include "isoprop/status.h"
#include "isoprop/volume.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ip_field {
    IP_FIELD_SHEPP_LOGAN = 0,   /* 3D Shepp-Logan head phantom (Kak & Slaney ellipsoids) */
    IP_FIELD_SPHERE = 1,        /* radial distance field, brightest at the centre */
    IP_FIELD_GYROID = 2,        /* sin x cos y + sin y cos z + sin z cos x, several periods */
    IP_FIELD_MARSCHNER_LOBB = 3 /* the Marschner-Lobb test signal (fM = 6, alpha = 0.25) */
} ip_field;

typedef struct ip_gen_params {
    ip_field field;
    uint32_t dims[3];   /* samples along x, y, z; each >= 2 */
    ip_type type;
    double noise;       /* standard deviation of added Gaussian noise, in the field's [0,1]
                           units before conversion to `type`; 0 for none */
    uint64_t seed;      /* noise seed; the noise of a sample depends only on seed and index */
} ip_gen_params;

/*! ip_field_name() : "shepp-logan", "sphere", "gyroid" or "marschner-lobb". */
const char *ip_field_name(ip_field field);

/*! ip_field_parse() : parses a field name. @return IP_OK or IP_ERR_ARGUMENT. */
ip_status ip_field_parse(const char *name, ip_field *out);

/*! ip_generate_plane() : writes z-plane `z` (dims[0]*dims[1] samples of params->type, host
 *  byte order) into `dst`, which the caller owns. Thread-safe. @return IP_OK or IP_ERR_ARGUMENT. */
ip_status ip_generate_plane(const ip_gen_params *params, uint32_t z, void *dst, ip_error *err);

/*! ip_generate_write() : writes the whole volume as a little-endian raw file at `path`,
 *  atomically (a temporary file in the same folder, fsync, rename); memory is O(one plane).
 *  With force == 0 an existing `path` is an IP_ERR_EXISTS error and is left untouched. */
ip_status ip_generate_write(const ip_gen_params *params, const char *path, int force,
                            ip_error *err);

/*! ip_upsample_write() : writes `input` enlarged `factor` times along each axis (dims * factor
 *  samples) by trilinear interpolation, as a little-endian raw file of the input's type at
 *  `path`, atomically; memory is O(a few planes). factor >= 1. */
ip_status ip_upsample_write(const ip_input_desc *input, uint32_t factor, const char *path,
                            int force, ip_error *err);

/*! ip_raw_file_name() : writes the conventional name "NAME_XxYxZ_TYPE.raw" for `name`, `dims`
 *  and `type` into buf (size bytes). @return IP_OK, or IP_ERR_ARGUMENT if it does not fit. */
ip_status ip_raw_file_name(char *buf, size_t size, const char *name, const uint32_t dims[3],
                           ip_type type);

#ifdef __cplusplus
}
#endif
#endif
