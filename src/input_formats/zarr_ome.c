/* SPDX-License-Identifier: BSD-3-Clause */
/* OME-Zarr images (NGFF 0.4: .zattrs of a Zarr v2 group; 0.5: zarr.json's attributes.ome of a
 * Zarr v3 group): the multiscales' axes, the chosen scale's array and its scale and
 * translation as spacing and origin. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "zarr.h"

/* The JSON object of `path` into *out; *out NULL and IP_OK when the file does not exist. */
static ip_status json_file(const char *path, cJSON **out, ip_error *err)
{
    char *text;
    int missing;
    *out = NULL;
    ip_status s = ip__zarr_read_text(path, &text, &missing, err);
    if (s != IP_OK || missing)
        return s;
    *out = cJSON_Parse(text);
    free(text);
    if (cJSON_IsObject(*out))
        return IP_OK;
    cJSON_Delete(*out);
    *out = NULL;
    return ip__fail(err, IP_ERR_INPUT, "%s: not JSON (or not a JSON object)", path);
}

/* The OME length units this reader converts between: their symbol and the power of ten of a
 * metre they are (micrometer: "um", -6). */
static const struct {
    const char *name, *symbol;
    int exponent;
} lengths[] = {{"kilometer", "km", 3},   {"meter", "m", 0},        {"centimeter", "cm", -2},
               {"millimeter", "mm", -3}, {"micrometer", "um", -6}, {"nanometer", "nm", -9},
               {"picometer", "pm", -12}};

/* The unit's power of ten, 99 when it is not one of lengths[]. */
static int metre_exponent(const char *unit)
{
    for (size_t i = 0; unit && i < sizeof lengths / sizeof lengths[0]; i++)
        if (!strcmp(unit, lengths[i].name))
            return lengths[i].exponent;
    return 99;
}

void ip__zarr_unit_symbol(const char *unit, char *out, size_t size)
{
    for (size_t i = 0; i < sizeof lengths / sizeof lengths[0]; i++)
        if (!strcmp(unit, lengths[i].name)) {
            snprintf(out, size, "%s", lengths[i].symbol);
            return;
        }
    ip__zarr_shown(unit, out, size);
}

/* Each axis' role ('x', 'y', 'z', 't', 'c') from its name (or, for another name, its type
 * time or channel); the last three must be z, y, x. */
static ip_status read_axes(const char *name, const cJSON *axes, zarr_ome *o, const char **units,
                           ip_error *err)
{
    char shown[48];
    int n = cJSON_IsArray(axes) ? cJSON_GetArraySize(axes) : 0;
    if (n < 3 || n > ZARR_MAX_DIMS)
        return ip__fail(err, IP_ERR_INPUT, "%s: multiscales 'axes' is not a list of 3 to 5 axes",
                        name);
    for (int i = 0; i < n; i++) {
        const cJSON *a = cJSON_GetArrayItem(axes, i);
        const char *axis = cJSON_IsString(a)
                               ? a->valuestring
                               : cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(a, "name"));
        const char *type = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(a, "type"));
        units[i] = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(a, "unit"));
        if (!axis)
            return ip__fail(err, IP_ERR_INPUT, "%s: axis %d has no name", name, i);
        if (strlen(axis) == 1 && strchr("xyztc", axis[0]))
            o->axis[i] = axis[0];
        else if (type && (!strcmp(type, "time") || !strcmp(type, "channel")))
            o->axis[i] = type[0];
        else
            return ip__fail(err, IP_ERR_INPUT, "%s: axis '%s' is not read (t, c, z, y, x are)",
                            name, ip__zarr_shown(axis, shown, sizeof shown));
    }
    if (o->axis[n - 3] != 'z' || o->axis[n - 2] != 'y' || o->axis[n - 1] != 'x')
        return ip__fail(err, IP_ERR_INPUT, "%s: the last three axes are not z, y, x", name);
    o->ndim = (uint32_t)n;
    return IP_OK;
}

/* Applies a coordinateTransformations list (scale, then translation) to scale[] and shift[]:
 * a point p maps to p * scale + shift. */
static ip_status transforms(const char *name, const cJSON *list, uint32_t n, double *scale,
                            double *shift, ip_error *err)
{
    char shown[48];
    const cJSON *t;
    cJSON_ArrayForEach(t, list)
    {
        const char *type = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(t, "type"));
        int is_scale = type && !strcmp(type, "scale");
        if (!type || (!is_scale && strcmp(type, "translation") != 0))
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: coordinate transformation '%s' is not read (scale and "
                            "translation are)",
                            name, ip__zarr_shown(type, shown, sizeof shown));
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(t, type);
        if (cJSON_GetArraySize(v) != (int)n)
            return ip__fail(err, IP_ERR_INPUT, "%s: a %s of %d values for %u axes", name, type,
                            cJSON_GetArraySize(v), n);
        for (uint32_t i = 0; i < n; i++) {
            const cJSON *x = cJSON_GetArrayItem(v, (int)i);
            if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble))
                return ip__fail(err, IP_ERR_INPUT, "%s: a %s value is not a number", name, type);
            if (is_scale) {
                scale[i] *= x->valuedouble;
                shift[i] *= x->valuedouble;
            } else {
                shift[i] += x->valuedouble;
            }
        }
    }
    return IP_OK;
}

/* The spatial units: kept when the three agree, else y and z converted to x's. */
static ip_status spatial_units(const char *name, zarr_ome *o, const char **units, double *scale,
                               double *shift, ip_error *err)
{
    uint32_t n = o->ndim;
    const char *ux = units[n - 1];
    char shown[48], shown_x[48];
    ip__zarr_shown(ux ? ux : "", o->unit, sizeof o->unit);
    for (uint32_t i = n - 3; i < n - 1; i++) {
        const char *u = units[i];
        if ((!u && !ux) || (u && ux && !strcmp(u, ux)))
            continue;
        int from = metre_exponent(u), to = metre_exponent(ux);
        if (from == 99 || to == 99)
            return ip__fail(err, IP_ERR_INPUT, "%s: axes in units %s and %s, which do not convert",
                            name, ip__zarr_shown(u, shown, sizeof shown),
                            ip__zarr_shown(ux, shown_x, sizeof shown_x));
        /* a power of ten, applied as one so that 0.00125 mm gives 1.25 um exactly */
        for (int e = from; e > to; e--)
            scale[i] *= 10, shift[i] *= 10;
        for (int e = from; e < to; e++)
            scale[i] /= 10, shift[i] /= 10;
    }
    return IP_OK;
}

/* The multiscale object of .zattrs (0.4) or zarr.json (0.5, attributes.ome); NULL when none. */
static const cJSON *multiscale_of(const cJSON *root, int v3)
{
    const cJSON *attrs = v3 ? cJSON_GetObjectItemCaseSensitive(root, "attributes") : root;
    const cJSON *ome = cJSON_GetObjectItemCaseSensitive(attrs, "ome");
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(ome ? ome : attrs, "multiscales");
    return cJSON_GetArrayItem(list, 0);
}

static ip_status read_multiscale(const char *name, const char *folder, const cJSON *ms,
                                 uint32_t scale, zarr_ome *o, ip_error *err)
{
    const char *units[ZARR_MAX_DIMS] = {0};
    double factor[ZARR_MAX_DIMS], shift[ZARR_MAX_DIMS] = {0};
    const cJSON *datasets = cJSON_GetObjectItemCaseSensitive(ms, "datasets");
    ip_status s = read_axes(name, cJSON_GetObjectItemCaseSensitive(ms, "axes"), o, units, err);
    if (s != IP_OK)
        return s;
    o->scales = (uint32_t)(cJSON_IsArray(datasets) ? cJSON_GetArraySize(datasets) : 0);
    if (o->scales == 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: multiscales has no datasets", name);
    if (scale >= o->scales)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: scale %u asked for, but the image has %u (0 .. %u)", name, scale,
                        o->scales, o->scales - 1);
    const cJSON *d = cJSON_GetArrayItem(datasets, (int)scale);
    const char *path = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(d, "path"));
    int control = 0;
    for (const char *c = path; c && *c; c++)
        control |= (unsigned char)*c < 0x20;
    if (!path || !path[0] || strstr(path, "..") || control)
        return ip__fail(err, IP_ERR_INPUT, "%s: dataset %u has no usable path", name, scale);
    if (snprintf(o->array, sizeof o->array, "%s/%s", folder, path) >= (int)sizeof o->array)
        return ip__fail(err, IP_ERR_INPUT, "%s: dataset path too long", name);
    for (uint32_t i = 0; i < o->ndim; i++)
        factor[i] = 1;
    if ((s = transforms(name, cJSON_GetObjectItemCaseSensitive(d, "coordinateTransformations"),
                        o->ndim, factor, shift, err)) != IP_OK ||
        (s = transforms(name, cJSON_GetObjectItemCaseSensitive(ms, "coordinateTransformations"),
                        o->ndim, factor, shift, err)) != IP_OK ||
        (s = spatial_units(name, o, units, factor, shift, err)) != IP_OK)
        return s;
    for (int a = 0; a < 3; a++) {
        o->spacing[a] = fabs(factor[o->ndim - 1 - a]);
        o->origin[a] = shift[o->ndim - 1 - a];
    }
    return IP_OK;
}

ip_status ip__zarr_read_ome(const char *folder, uint32_t scale, int *is_ome, zarr_ome *o,
                            ip_error *err)
{
    char name[IP_PATH_MAX + 16];
    cJSON *root = NULL;
    int v3 = 0;
    memset(o, 0, sizeof *o);
    *is_ome = 0;
    snprintf(name, sizeof name, "%s/.zattrs", folder);
    ip_status s = json_file(name, &root, err);
    if (s == IP_OK && !root) {
        v3 = 1;
        snprintf(name, sizeof name, "%s/zarr.json", folder);
        s = json_file(name, &root, err);
    }
    if (s != IP_OK || !root)
        return s;
    const cJSON *ms = multiscale_of(root, v3);
    if (ms) {
        *is_ome = 1;
        s = read_multiscale(name, folder, ms, scale, o, err);
    }
    cJSON_Delete(root);
    return s;
}
