/* SPDX-License-Identifier: BSD-3-Clause */
/* TIFF input through libtiff: a multi-page TIFF file (every page a z-plane) or a folder of
 * numbered single-page TIFF files (every file a z-plane, in the order of the number in its
 * name). Pages hold one sample per pixel: 8-bit unsigned, 16-bit unsigned or signed, 32-bit
 * IEEE float, in strips or tiles, compressed with any codec this libtiff decodes. A plane is
 * decoded straight into the reader's buffer (tiles through one tile's buffer), so memory stays
 * at one plane whatever the number of pages. libtiff's messages go, per handle, into the
 * error of the call (TIFFOpenOptionsSetErrorHandlerExtR): no global handler is installed. */
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <tiffio.h>
#include <unistd.h>

#include "readers.h"
#include "internal.h"

/* ---- one open TIFF file ---- */

/* An open TIFF and the first error libtiff reported about it (the handle's own handler). */
typedef struct tiff_file {
    TIFF *tif;
    char path[IP_PATH_MAX];
    char message[512]; /* "" until libtiff reports an error */
} tiff_file;

static int on_tiff_error(TIFF *tif, void *user, const char *module, const char *fmt, va_list ap)
{
    tiff_file *f = user;
    (void)tif, (void)module;
    if (f->message[0] == '\0') {
        vsnprintf(f->message, sizeof f->message, fmt, ap);
        for (char *c = f->message; *c; c++)
            if (*c == '\n' || *c == '\r')
                *c = ' ';
    }
    return 1; /* handled: the global handlers (stderr) are not called */
}

static int on_tiff_warning(TIFF *tif, void *user, const char *module, const char *fmt, va_list ap)
{
    (void)tif, (void)user, (void)module, (void)fmt, (void)ap;
    return 1; /* unknown tags and the like: nothing the samples depend on */
}

/* What libtiff said, or `otherwise` when it said nothing. */
static const char *tiff_reason(const tiff_file *f, const char *otherwise)
{
    return f->message[0] ? f->message : otherwise;
}

/* Opens `path` (a regular file; a FIFO or device is refused, never waited on) into *f, whose
 * address libtiff keeps until tiff_close(). */
static ip_status tiff_open_file(tiff_file *f, const char *path, ip_error *err)
{
    memset(f, 0, sizeof *f);
    snprintf(f->path, sizeof f->path, "%s", path);
    int fd;
    ip_status st = ip__input_open_regular(path, &fd, err);
    if (st != IP_OK)
        return st;
    TIFFOpenOptions *options = TIFFOpenOptionsAlloc();
    if (!options) {
        close(fd);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    }
    TIFFOpenOptionsSetErrorHandlerExtR(options, on_tiff_error, f);
    TIFFOpenOptionsSetWarningHandlerExtR(options, on_tiff_warning, f);
    /* "m": read, not map: a file cut short while mapped would end the process with SIGBUS */
    f->tif = TIFFFdOpenExt(fd, path, "rm", options);
    TIFFOpenOptionsFree(options);
    if (!f->tif) {
        close(fd);
        return ip__fail(err, IP_ERR_INPUT, "%s: not a readable TIFF file: %s", path,
                        tiff_reason(f, "libtiff cannot open it"));
    }
    return IP_OK;
}

static void tiff_close(tiff_file *f)
{
    if (f->tif)
        TIFFClose(f->tif); /* closes the descriptor too */
    f->tif = NULL;
}

/* ---- one page: its layout and its samples ---- */

typedef struct tiff_page {
    uint32_t width, height;
    ip_type type;
    int tiled;
} tiff_page;

/* "FILE" for a single-page file, "FILE: page N" (from 1) for a page of a multi-page one. */
static void page_label(const tiff_file *f, uint32_t page, int multi, char *out, size_t size)
{
    if (multi)
        snprintf(out, size, "%s: page %u", f->path, page + 1);
    else
        snprintf(out, size, "%s", f->path);
}

static ip_status sample_type(const char *label, uint16_t bits, uint16_t format, ip_type *type,
                             ip_error *err)
{
    static const char *const formats[] = {
        "?",    "unsigned integer", "signed integer", "IEEE float",
        "void", "complex integer",  "complex float"};
    if (bits == 8 && format == SAMPLEFORMAT_UINT)
        *type = IP_UINT8;
    else if (bits == 16 && format == SAMPLEFORMAT_UINT)
        *type = IP_UINT16;
    else if (bits == 16 && format == SAMPLEFORMAT_INT)
        *type = IP_INT16;
    else if (bits == 32 && format == SAMPLEFORMAT_IEEEFP)
        *type = IP_FLOAT32;
    else
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: %u-bit %s samples are not supported (8-bit unsigned, 16-bit "
                        "unsigned or signed, 32-bit float are)",
                        label, bits, format < 7 ? formats[format] : "unknown-format");
    return IP_OK;
}

static ip_status check_photometric(TIFF *tif, const char *label, ip_error *err)
{
    uint16_t samples = 1, photometric = PHOTOMETRIC_MINISBLACK;
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
    if (samples != 1)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: %u samples per pixel (colour) are not supported; pages must be "
                        "greyscale, one sample per pixel",
                        label, samples);
    if (!TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &photometric))
        return IP_OK; /* absent: taken as grey, black at 0 */
    if (photometric == PHOTOMETRIC_PALETTE)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: palette colour pages are not supported; pages must be greyscale",
                        label);
    if (photometric != PHOTOMETRIC_MINISBLACK)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: photometric interpretation %u is not supported (only greyscale, "
                        "black at 0: MinIsBlack)",
                        label, photometric);
    return IP_OK;
}

static ip_status check_compression(TIFF *tif, const char *label, ip_error *err)
{
    uint16_t compression = COMPRESSION_NONE;
    TIFFGetFieldDefaulted(tif, TIFFTAG_COMPRESSION, &compression);
    if (TIFFIsCODECConfigured(compression))
        return IP_OK;
    const TIFFCodec *codec = TIFFFindCODEC(compression);
    return ip__fail(err, IP_ERR_UNSUPPORTED,
                    "%s: compression %u (%s) cannot be decoded by this libtiff; save the pages "
                    "uncompressed or with LZW, deflate or PackBits",
                    label, compression, codec ? codec->name : "unknown");
}

/* Reads the layout of the current page of f and checks that it can be read. */
static ip_status read_page(const tiff_file *f, const char *label, tiff_page *page, ip_error *err)
{
    uint16_t bits = 1, format = SAMPLEFORMAT_UINT;
    ip_status st;
    memset(page, 0, sizeof *page);
    if (!TIFFGetField(f->tif, TIFFTAG_IMAGEWIDTH, &page->width) ||
        !TIFFGetField(f->tif, TIFFTAG_IMAGELENGTH, &page->height))
        return ip__fail(err, IP_ERR_INPUT, "%s: the page has no width or height", label);
    TIFFGetFieldDefaulted(f->tif, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(f->tif, TIFFTAG_SAMPLEFORMAT, &format);
    if ((st = check_photometric(f->tif, label, err)) != IP_OK ||
        (st = sample_type(label, bits, format, &page->type, err)) != IP_OK ||
        (st = check_compression(f->tif, label, err)) != IP_OK)
        return st;
    page->tiled = TIFFIsTiled(f->tif);
    return IP_OK;
}

/* IP_ERR_INPUT unless `page` has the width, height and type of `first`. */
static ip_status same_layout(const char *label, const tiff_page *page, const tiff_page *first,
                             const char *first_name, ip_error *err)
{
    if (page->width == first->width && page->height == first->height && page->type == first->type)
        return IP_OK;
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: %ux%u %s differs from %ux%u %s of %s; every plane needs one size and "
                    "type",
                    label, page->width, page->height, ip_type_name(page->type), first->width,
                    first->height, ip_type_name(first->type), first_name);
}

static ip_status decode_failed(const tiff_file *f, const char *label, const char *what,
                               uint32_t index, ip_error *err)
{
    return ip__fail(err, IP_ERR_INPUT, "%s: %s %u does not decode: %s", label, what, index,
                    tiff_reason(f, "it holds too few bytes"));
}

/* The samples of a page in strips, each decoded straight into its rows of dst. */
static ip_status read_strips(tiff_file *f, const char *label, const tiff_page *page,
                             unsigned char *dst, ip_error *err)
{
    uint32_t per_strip = page->height;
    size_t row_bytes = (size_t)page->width * ip_type_size(page->type);
    TIFFGetFieldDefaulted(f->tif, TIFFTAG_ROWSPERSTRIP, &per_strip);
    if (per_strip == 0 || per_strip > page->height)
        per_strip = page->height;
    uint32_t strips = TIFFNumberOfStrips(f->tif);
    if ((uint64_t)strips * per_strip < page->height)
        return ip__fail(err, IP_ERR_INPUT, "%s: %u strips of %u rows miss rows of the %u", label,
                        strips, per_strip, page->height);
    for (uint32_t s = 0; (uint64_t)s * per_strip < page->height; s++) {
        uint32_t row = s * per_strip;
        uint32_t rows = page->height - row < per_strip ? page->height - row : per_strip;
        tmsize_t want = (tmsize_t)(rows * row_bytes);
        if (TIFFReadEncodedStrip(f->tif, s, dst + row * row_bytes, want) != want)
            return decode_failed(f, label, "strip", s, err);
    }
    return IP_OK;
}

/* The samples of a tiled page, each tile decoded into one tile's buffer and its part inside
 * the page copied to dst. */
static ip_status read_tiles(tiff_file *f, const char *label, const tiff_page *page,
                            unsigned char *dst, ip_error *err)
{
    uint32_t tile_w = 0, tile_h = 0;
    size_t sample = ip_type_size(page->type);
    if (!TIFFGetField(f->tif, TIFFTAG_TILEWIDTH, &tile_w) ||
        !TIFFGetField(f->tif, TIFFTAG_TILELENGTH, &tile_h) || tile_w == 0 || tile_h == 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: a tiled page without a tile size", label);
    tmsize_t tile_bytes = (tmsize_t)((uint64_t)tile_w * tile_h * sample);
    unsigned char *tile = malloc((size_t)tile_bytes);
    if (!tile)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for a %ux%u tile", label, tile_w,
                        tile_h);
    for (uint32_t y = 0; y < page->height; y += tile_h) {
        for (uint32_t x = 0; x < page->width; x += tile_w) {
            uint32_t t = TIFFComputeTile(f->tif, x, y, 0, 0);
            if (TIFFReadEncodedTile(f->tif, t, tile, tile_bytes) != tile_bytes) {
                free(tile);
                return decode_failed(f, label, "tile", t, err);
            }
            uint32_t cols = page->width - x < tile_w ? page->width - x : tile_w;
            uint32_t rows = page->height - y < tile_h ? page->height - y : tile_h;
            for (uint32_t r = 0; r < rows; r++)
                memcpy(dst + ((size_t)(y + r) * page->width + x) * sample,
                       tile + (size_t)r * tile_w * sample, (size_t)cols * sample);
        }
    }
    free(tile);
    return IP_OK;
}

/* Reads the current page of f, which must have the layout `want`, into dst. */
static ip_status read_page_samples(tiff_file *f, const char *label, const tiff_page *want,
                                   const char *want_name, void *dst, ip_error *err)
{
    tiff_page page;
    ip_status st = read_page(f, label, &page, err);
    if (st == IP_OK)
        st = same_layout(label, &page, want, want_name, err);
    if (st != IP_OK)
        return st;
    return page.tiled ? read_tiles(f, label, &page, dst, err)
                      : read_strips(f, label, &page, dst, err);
}

/* ---- a folder of numbered files ---- */

typedef struct tiff_slice {
    uint64_t number;
    char name[256];
} tiff_slice;

/* 1 for a name ending in .tif or .tiff, any case: the files a folder's slices are. */
static int is_tiff_name(const char *name)
{
    size_t n = strlen(name);
    return (n > 4 && strcasecmp(name + n - 4, ".tif") == 0) ||
           (n > 5 && strcasecmp(name + n - 5, ".tiff") == 0);
}

/* The slice number of a file: the last run of digits in its name. -1 when there is none (or
 * one past 18 digits). */
static int slice_number(const char *name, uint64_t *number)
{
    const char *end = NULL;
    for (const char *c = name; *c; c++)
        if (isdigit((unsigned char)*c))
            end = c + 1;
    if (!end)
        return -1;
    const char *start = end;
    while (start > name && isdigit((unsigned char)start[-1]))
        start--;
    while (start < end - 1 && *start == '0')
        start++;
    if (end - start > 18)
        return -1;
    *number = 0;
    for (const char *c = start; c < end; c++)
        *number = *number * 10 + (uint64_t)(*c - '0');
    return 0;
}

static int by_number(const void *a, const void *b)
{
    const tiff_slice *x = a, *y = b;
    return x->number < y->number ? -1 : x->number > y->number;
}

/* Adds the file `name` of `folder` to the list when it is a TIFF file. */
static ip_status add_slice(const char *folder, const char *name, tiff_slice **slices, size_t *count,
                           size_t *capacity, ip_error *err)
{
    char full[IP_PATH_MAX];
    if (name[0] == '.' || !is_tiff_name(name))
        return IP_OK;
    if (strlen(name) >= sizeof(*slices)->name ||
        snprintf(full, sizeof full, "%s/%s", folder, name) >= (int)sizeof full)
        return ip__fail(err, IP_ERR_INPUT, "%s: the file name %.64s... is too long", folder, name);
    if (*count == *capacity) {
        size_t grown = *capacity ? 2 * *capacity : 64;
        tiff_slice *more = realloc(*slices, grown * sizeof *more);
        if (!more)
            return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory listing the files", folder);
        *slices = more;
        *capacity = grown;
    }
    tiff_slice *s = &(*slices)[*count];
    snprintf(s->name, sizeof s->name, "%s", name);
    if (slice_number(name, &s->number) != 0)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: %s has no slice number in its name (each .tif/.tiff file of the "
                        "folder is one numbered slice)",
                        folder, name);
    (*count)++;
    return IP_OK;
}

/* Checks that the sorted numbers run without a repeat or a gap. */
static ip_status check_numbering(const char *folder, const tiff_slice *slices, size_t count,
                                 ip_error *err)
{
    for (size_t i = 1; i < count; i++) {
        const tiff_slice *a = &slices[i - 1], *b = &slices[i];
        if (a->number == b->number)
            return ip__fail(err, IP_ERR_INPUT, "%s: %s and %s have the same slice number %llu",
                            folder, a->name, b->name, (unsigned long long)a->number);
        if (b->number != a->number + 1) {
            if (b->number == a->number + 2)
                return ip__fail(err, IP_ERR_INPUT,
                                "%s: slice %llu is missing (the files go from %s to %s)", folder,
                                (unsigned long long)(a->number + 1), a->name, b->name);
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: slices %llu to %llu are missing (the files go from %s to %s)",
                            folder, (unsigned long long)(a->number + 1),
                            (unsigned long long)(b->number - 1), a->name, b->name);
        }
    }
    return IP_OK;
}

/*! list_slices() : the .tif/.tiff files of `folder` (other files are ignored) in the order of
 *  their numbers, which must run without a gap; *slices is the caller's to free(). */
static ip_status list_slices(const char *folder, tiff_slice **slices, size_t *count, ip_error *err)
{
    size_t capacity = 0;
    ip_status st = IP_OK;
    struct dirent *entry;
    *slices = NULL;
    *count = 0;
    DIR *dir = opendir(folder);
    if (!dir)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open the folder", folder);
    while (st == IP_OK && (entry = readdir(dir)) != NULL)
        st = add_slice(folder, entry->d_name, slices, count, &capacity, err);
    closedir(dir);
    if (st == IP_OK && *count == 0)
        st = ip__fail(err, IP_ERR_INPUT, "%s: the folder holds no .tif or .tiff files", folder);
    if (st == IP_OK) {
        qsort(*slices, *count, sizeof **slices, by_number);
        st = check_numbering(folder, *slices, *count, err);
    }
    if (st != IP_OK) {
        free(*slices);
        *slices = NULL;
    }
    return st;
}

/* ---- spacing from ImageJ's description ---- */

/* What an ImageJ stack says of itself in its ImageDescription ("ImageJ=1.54f\nimages=40\n
 * spacing=2.5\nunit=micron\n..."). */
typedef struct imagej_info {
    int present;
    double spacing; /* z, in ImageJ's unit; 0 when not given */
    uint64_t images, channels, frames;
} imagej_info;

static void imagej_value(const char *text, const char *key, double *out)
{
    size_t n = strlen(key);
    for (const char *line = text; line && *line; line = strchr(line, '\n')) {
        line += *line == '\n';
        if (strncmp(line, key, n) == 0 && line[n] == '=') {
            *out = strtod(line + n + 1, NULL);
            return;
        }
    }
}

static void read_imagej(TIFF *tif, imagej_info *info)
{
    const char *text = NULL;
    double images = 0, channels = 1, frames = 1;
    memset(info, 0, sizeof *info);
    if (!TIFFGetField(tif, TIFFTAG_IMAGEDESCRIPTION, &text) || strncmp(text, "ImageJ=", 7) != 0)
        return;
    info->present = 1;
    imagej_value(text, "spacing", &info->spacing);
    imagej_value(text, "images", &images);
    imagej_value(text, "channels", &channels);
    imagej_value(text, "frames", &frames);
    info->images = images >= 0 && images < 1e18 ? (uint64_t)images : 0;
    info->channels = channels >= 1 && channels < 1e18 ? (uint64_t)channels : 1;
    info->frames = frames >= 1 && frames < 1e18 ? (uint64_t)frames : 1;
}

/* ImageJ stores the pixel size as XResolution/YResolution (pixels per unit) and the slice
 * distance as spacing=, all in its unit (usually micron). Other TIFFs carry no z spacing. */
static void imagej_spacing(TIFF *tif, const imagej_info *info, double spacing[3])
{
    float rx = 0, ry = 0;
    if (!info->present)
        return;
    if (TIFFGetField(tif, TIFFTAG_XRESOLUTION, &rx) && rx > 0)
        spacing[0] = 1.0 / rx;
    if (TIFFGetField(tif, TIFFTAG_YRESOLUTION, &ry) && ry > 0)
        spacing[1] = 1.0 / ry;
    if (info->spacing > 0)
        spacing[2] = info->spacing;
}

static ip_status check_imagej(const char *path, const imagej_info *info, uint64_t pages,
                              ip_error *err)
{
    if (!info->present)
        return IP_OK;
    if (info->channels > 1 || info->frames > 1)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: an ImageJ hyperstack of %llu channels and %llu frames; only stacks "
                        "of one channel and one frame are supported",
                        path, (unsigned long long)info->channels, (unsigned long long)info->frames);
    if (info->images > pages)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: ImageJ says %llu images but the file has %llu pages (ImageJ's "
                        "layout past 4 GiB); read it as raw data with --dims and --type",
                        path, (unsigned long long)info->images, (unsigned long long)pages);
    return IP_OK;
}

/* ---- describing ---- */

/* What describing found: the first plane's layout, the number of planes, the spacing. */
typedef struct tiff_layout {
    tiff_page first;
    uint64_t planes;
    imagej_info imagej;
    double spacing[3];
} tiff_layout;

/* The first page's layout and what ImageJ says, from the open file f. */
static ip_status read_first(const tiff_file *f, const char *label, tiff_layout *layout,
                            ip_error *err)
{
    for (int axis = 0; axis < 3; axis++)
        layout->spacing[axis] = 1.0;
    read_imagej(f->tif, &layout->imagej);
    imagej_spacing(f->tif, &layout->imagej, layout->spacing);
    return read_page(f, label, &layout->first, err);
}

static ip_status describe_file(const char *path, tiff_layout *layout, ip_error *err)
{
    tiff_file f;
    char label[IP_PATH_MAX + 32], first_label[IP_PATH_MAX + 32];
    ip_status st = tiff_open_file(&f, path, err);
    if (st != IP_OK)
        return st;
    page_label(&f, 0, 1, first_label, sizeof first_label);
    st = read_first(&f, first_label, layout, err);
    for (layout->planes = 1; st == IP_OK && TIFFReadDirectory(f.tif); layout->planes++) {
        tiff_page page;
        page_label(&f, (uint32_t)layout->planes, 1, label, sizeof label);
        if ((st = read_page(&f, label, &page, err)) == IP_OK)
            st = same_layout(label, &page, &layout->first, "page 1", err);
    }
    if (st == IP_OK && f.message[0]) /* TIFFReadDirectory failed, not ended */
        st = ip__fail(err, IP_ERR_INPUT, "%s: page %llu cannot be read: %s", path,
                      (unsigned long long)layout->planes + 1, f.message);
    if (st == IP_OK)
        st = check_imagej(path, &layout->imagej, layout->planes, err);
    tiff_close(&f);
    return st;
}

/* Opens the slice `name` of `folder` into f; it must hold one page. */
static ip_status open_slice(tiff_file *f, const char *folder, const char *name, ip_error *err)
{
    char full[IP_PATH_MAX];
    if (snprintf(full, sizeof full, "%s/%s", folder, name) >= (int)sizeof full)
        return ip__fail(err, IP_ERR_INPUT, "%s: the path of %s is too long", folder, name);
    return tiff_open_file(f, full, err);
}

static ip_status check_single_page(tiff_file *f, ip_error *err)
{
    if (!TIFFReadDirectory(f->tif))
        return IP_OK;
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: a file of several pages in a folder of slices (each file must be one "
                    "page)",
                    f->path);
}

/* Every slice is opened once, so that a mixed folder fails here and not after a long run. */
static ip_status describe_folder(const char *path, tiff_layout *layout, ip_error *err)
{
    tiff_slice *slices;
    size_t count;
    ip_status st = list_slices(path, &slices, &count, err);
    char first_name[IP_PATH_MAX];
    for (size_t i = 0; st == IP_OK && i < count; i++) {
        tiff_file f;
        tiff_page page;
        if ((st = open_slice(&f, path, slices[i].name, err)) != IP_OK)
            break;
        if (i == 0) {
            snprintf(first_name, sizeof first_name, "%s", f.path);
            st = read_first(&f, f.path, layout, err);
        } else if ((st = read_page(&f, f.path, &page, err)) == IP_OK) {
            st = same_layout(f.path, &page, &layout->first, first_name, err);
        }
        if (st == IP_OK)
            st = check_single_page(&f, err);
        tiff_close(&f);
    }
    layout->planes = count;
    free(slices);
    return st;
}

/* Dims and type come from the pages; an override may repeat them but not change them. */
static ip_status check_overrides(const char *path, const tiff_layout *layout,
                                 const ip_input_overrides *overrides, ip_error *err)
{
    const uint64_t dims[3] = {layout->first.width, layout->first.height, layout->planes};
    if (ip__text_overridden(BY_DIMS, overrides) &&
        (overrides->dims[0] != dims[0] || overrides->dims[1] != dims[1] ||
         overrides->dims[2] != dims[2]))
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the dims given, %ux%ux%u, differ from the TIFF's %llux%llux%llu "
                        "(a TIFF's dims cannot be overridden)",
                        path, overrides->dims[0], overrides->dims[1], overrides->dims[2],
                        (unsigned long long)dims[0], (unsigned long long)dims[1],
                        (unsigned long long)dims[2]);
    if (ip__text_overridden(BY_TYPE, overrides) && overrides->type != layout->first.type)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the type given, %s, differs from the TIFF's %s (a TIFF's type "
                        "cannot be overridden)",
                        path, ip_type_name(overrides->type), ip_type_name(layout->first.type));
    return IP_OK;
}

ip_status ip__tiff_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    struct stat st;
    tiff_layout layout;
    ip_status status;
    if (stat(path, &st) != 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", path);
    status = S_ISDIR(st.st_mode) ? describe_folder(path, &layout, err)
                                 : describe_file(path, &layout, err);
    if (status == IP_OK)
        status = check_overrides(path, &layout, overrides, err);
    if (status != IP_OK)
        return status;
    desc->encoding = IP_ENCODING_TIFF;
    desc->type = layout.first.type;
    found->has_type = 1;
    found->has_dims = 1;
    found->dims[0] = layout.first.width;
    found->dims[1] = layout.first.height;
    found->dims[2] = layout.planes;
    if (!ip__text_overridden(BY_SPACING, overrides))
        memcpy(desc->spacing, layout.spacing, sizeof desc->spacing);
    return IP_OK;
}

/* ---- the plane source ---- */

typedef struct tiff_source {
    char path[IP_PATH_MAX];
    tiff_page want;     /* the layout of the description: every plane must have it */
    tiff_slice *slices; /* a folder's files; NULL for a multi-page file */
    size_t count;
    tiff_file file; /* the multi-page file, open from start to end */
} tiff_source;

static void tiff_source_close(void *state)
{
    tiff_source *s = state;
    if (!s)
        return;
    tiff_close(&s->file);
    free(s->slices);
    free(s);
}

static ip_status tiff_source_open(const ip_input_desc *desc, void **state, ip_error *err)
{
    struct stat st;
    ip_status status;
    tiff_source *s = calloc(1, sizeof *s);
    *state = s;
    if (!s)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", desc->path);
    snprintf(s->path, sizeof s->path, "%s", desc->path);
    s->want.width = desc->dims[0];
    s->want.height = desc->dims[1];
    s->want.type = desc->type;
    if (stat(desc->path, &st) != 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", desc->path);
    if (!S_ISDIR(st.st_mode))
        return tiff_open_file(&s->file, desc->path, err);
    if ((status = list_slices(desc->path, &s->slices, &s->count, err)) != IP_OK)
        return status;
    if (s->count != desc->dims[2])
        return ip__fail(err, IP_ERR_INPUT, "%s: the folder now holds %zu slices, not %u",
                        desc->path, s->count, desc->dims[2]);
    return IP_OK;
}

static ip_status tiff_source_read_plane(void *state, uint32_t z, void *dst, ip_error *err)
{
    tiff_source *s = state;
    char label[IP_PATH_MAX + 32];
    ip_status status;
    if (s->slices) {
        tiff_file f;
        if ((status = open_slice(&f, s->path, s->slices[z].name, err)) != IP_OK)
            return status;
        status = read_page_samples(&f, f.path, &s->want, "the description", dst, err);
        tiff_close(&f);
        return status;
    }
    page_label(&s->file, z, 1, label, sizeof label);
    if (z > 0 && !TIFFReadDirectory(s->file.tif))
        return ip__fail(err, IP_ERR_INPUT, "%s: the page is missing (the file changed?): %s", label,
                        tiff_reason(&s->file, "no more pages"));
    return read_page_samples(&s->file, label, &s->want, "the description", dst, err);
}

const ip__plane_source ip__tiff_source = {tiff_source_open, tiff_source_read_plane,
                                          tiff_source_close};
