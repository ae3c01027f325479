/* SPDX-License-Identifier: BSD-3-Clause */
/* Sample types, dimension parsing and small platform helpers. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include "internal.h"
#include "isoprop/volume.h"

size_t ip_type_size(ip_type type)
{
    switch (type) {
    case IP_UINT8: return 1;
    case IP_UINT16:
    case IP_INT16: return 2;
    case IP_FLOAT32: return 4;
    }
    return 0;
}

/* Every name of every type, and who uses it: ip_type_parse() accepts them all, a header
 * reader only its format's spellings. The first name of a type is its canonical one. */
enum {
    CANONICAL = IP_TYPE_SPELLING_CANONICAL,
    NRRD = IP_TYPE_SPELLING_NRRD,
    META = IP_TYPE_SPELLING_METAIMAGE,
    OTHER = IP_TYPE_SPELLING_OTHER
};
static const struct {
    const char *name;
    ip_type type;
    unsigned spellings;
} type_names[] = {
    {"uint8", IP_UINT8, CANONICAL | NRRD},
    {"uint16", IP_UINT16, CANONICAL | NRRD},
    {"int16", IP_INT16, CANONICAL | NRRD},
    {"float32", IP_FLOAT32, CANONICAL},
    {"uchar", IP_UINT8, NRRD},
    {"unsigned char", IP_UINT8, NRRD},
    {"uint8_t", IP_UINT8, NRRD},
    {"MET_UCHAR", IP_UINT8, META},
    {"u8", IP_UINT8, OTHER},
    {"ushort", IP_UINT16, NRRD},
    {"unsigned short", IP_UINT16, NRRD},
    {"unsigned short int", IP_UINT16, NRRD},
    {"uint16_t", IP_UINT16, NRRD},
    {"MET_USHORT", IP_UINT16, META},
    {"u16", IP_UINT16, OTHER},
    {"short", IP_INT16, NRRD},
    {"short int", IP_INT16, NRRD},
    {"signed short", IP_INT16, NRRD},
    {"signed short int", IP_INT16, NRRD},
    {"int16_t", IP_INT16, NRRD},
    {"MET_SHORT", IP_INT16, META},
    {"i16", IP_INT16, OTHER},
    {"float", IP_FLOAT32, NRRD},
    {"MET_FLOAT", IP_FLOAT32, META},
    {"f32", IP_FLOAT32, OTHER},
};

const char *ip_type_name(ip_type type)
{
    for (size_t i = 0; i < sizeof type_names / sizeof type_names[0]; i++)
        if (type_names[i].type == type && (type_names[i].spellings & CANONICAL))
            return type_names[i].name;
    return "unknown";
}

ip_status ip__type_from_name(const char *name, unsigned spellings, ip_type *out)
{
    if (!name)
        return IP_ERR_ARGUMENT;
    for (size_t i = 0; i < sizeof type_names / sizeof type_names[0]; i++) {
        if ((type_names[i].spellings & spellings) && strcasecmp(name, type_names[i].name) == 0) {
            *out = type_names[i].type;
            return IP_OK;
        }
    }
    return IP_ERR_ARGUMENT;
}

int ip_type_holds(ip_type type, float value)
{
    switch (type) {
    case IP_UINT8: return value >= 0.0f && value <= 255.0f && value == floorf(value);
    case IP_UINT16: return value >= 0.0f && value <= 65535.0f && value == floorf(value);
    case IP_INT16: return value >= -32768.0f && value <= 32767.0f && value == floorf(value);
    case IP_FLOAT32: return isfinite(value);
    }
    return 0;
}

void ip__type_names(unsigned spellings, char *out, size_t size)
{
    size_t used = 0;
    out[0] = '\0';
    for (int type = IP_UINT8; type <= IP_FLOAT32; type++) {
        for (size_t i = 0; i < sizeof type_names / sizeof type_names[0]; i++) {
            if ((int)type_names[i].type != type || !(type_names[i].spellings & spellings))
                continue;
            int n = snprintf(out + used, size - used, "%s%s", used ? ", " : "", type_names[i].name);
            if (n < 0 || (size_t)n >= size - used)
                return; /* cut short, terminated */
            used += (size_t)n;
            break;
        }
    }
}

ip_status ip_type_parse(const char *name, ip_type *out)
{
    return ip__type_from_name(name, IP_TYPE_SPELLING_ALL, out);
}

/* The external definition of the inline one in isoprop/volume.h (C11 6.7.4), for callers
 * that take its address or do not inline it. */
extern float ip_sample_get(const void *samples, ip_type type, size_t index);

ip_status ip_dims_parse(const char *text, uint32_t dims[3])
{
    const char *p = text;
    uint32_t parsed[3];
    if (!text)
        return IP_ERR_ARGUMENT;
    for (int axis = 0; axis < 3; axis++) {
        if (*p < '0' || *p > '9')
            return IP_ERR_ARGUMENT;
        char *end;
        unsigned long long v = strtoull(p, &end, 10);
        if (v < 1 || v >= (1ull << 31))
            return IP_ERR_ARGUMENT;
        parsed[axis] = (uint32_t)v;
        p = end;
        if (axis < 2) {
            if (*p != 'x' && *p != 'X')
                return IP_ERR_ARGUMENT;
            p++;
        }
    }
    if (*p != '\0')
        return IP_ERR_ARGUMENT;
    memcpy(dims, parsed, sizeof parsed);
    return IP_OK;
}

ip_status ip_spacing_check(const double spacing[3], const char *name, ip_error *err)
{
    static const char axes[3] = {'x', 'y', 'z'};
    const char *who = name && name[0] ? name : "spacing";
    const char *sep = name && name[0] ? ": spacing" : "";
    for (int a = 0; a < 3; a++) {
        double s = spacing[a];
        if (!(s >= IP_SPACING_MIN && s <= IP_SPACING_MAX))
            return ip__fail(err, IP_ERR_UNSUPPORTED,
                            "%s%s %g along %c is outside the range that renders correctly, "
                            "%g to %g world units (express the spacing in another unit, e.g. "
                            "%s)",
                            who, sep, s, axes[a], IP_SPACING_MIN, IP_SPACING_MAX,
                            s < IP_SPACING_MIN ? "micrometres instead of metres"
                                               : "kilometres instead of metres");
    }
    int lo = 0, hi = 0;
    for (int a = 1; a < 3; a++) {
        if (spacing[a] < spacing[lo])
            lo = a;
        if (spacing[a] > spacing[hi])
            hi = a;
    }
    if (spacing[hi] > IP_SPACING_RATIO_MAX * spacing[lo])
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s%s %g,%g,%g: %g along %c is %g times %g along %c, more than the "
                        "%g times that renders correctly (resample the volume to a less "
                        "anisotropic grid)",
                        who, sep, spacing[0], spacing[1], spacing[2], spacing[hi], axes[hi],
                        spacing[hi] / spacing[lo], spacing[lo], axes[lo], IP_SPACING_RATIO_MAX);
    return IP_OK;
}

void ip__swap_bytes(void *data, size_t count, size_t size)
{
    unsigned char *p = data;
    if (size == 2) {
        for (size_t i = 0; i < count; i++, p += 2) {
            unsigned char t = p[0];
            p[0] = p[1];
            p[1] = t;
        }
    } else if (size == 4) {
        for (size_t i = 0; i < count; i++, p += 4) {
            unsigned char t0 = p[0], t1 = p[1];
            p[0] = p[3];
            p[1] = p[2];
            p[2] = t1;
            p[3] = t0;
        }
    }
}
