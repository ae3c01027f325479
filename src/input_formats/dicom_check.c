/* The structure of a DICOM Part 10 file, checked before GDCM parses it (dicom_check.h). Only
 * the element framing is read: tags, value representations and lengths, and the few values
 * that size the image (Rows, Columns, Samples per Pixel, Bits Allocated, Number of Frames). */
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dicom_check.h"

#define MAX_DEPTH 16               /* nested sequences */
#define UNDEFINED 0xFFFFFFFFu      /* an undefined length */
#define MAX_FILE ((size_t)1 << 31) /* larger files are not checked (none is a slice) */

/* What the walk needs and finds. */
typedef struct walk {
    const uint8_t *data;
    size_t size;
    int implicit, big; /* the data set's encoding */
    uint64_t rows, columns, samples, bits, frames;
    int has_pixels; /* the data set holds Pixel Data */
    char *why;
    size_t why_size;
} walk;

static unsigned u16(const walk *w, size_t at, int big)
{
    const uint8_t *p = w->data + at;
    return big ? (unsigned)p[0] << 8 | p[1] : (unsigned)p[1] << 8 | p[0];
}

static uint32_t u32(const walk *w, size_t at, int big)
{
    const uint8_t *p = w->data + at;
    return big ? (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]
               : (uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0];
}

static int fail(walk *w, size_t at, unsigned group, unsigned element, const char *what)
{
    snprintf(w->why, w->why_size,
             "not a well-formed DICOM file: %s at byte %zu (element %04X,%04X)", what, at, group,
             element);
    return -1;
}

/* Value representations whose length takes 4 bytes after 2 reserved ones (explicit VR). */
static int long_vr(const uint8_t *vr)
{
    static const char *const vrs[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                      "SV", "UC", "UN", "UR", "UT", "UV"};
    for (size_t i = 0; i < sizeof vrs / sizeof vrs[0]; i++)
        if (vr[0] == vrs[i][0] && vr[1] == vrs[i][1])
            return 1;
    return 0;
}

/* The integer value of a US element (or IS text, for Number of Frames). */
static void note_value(walk *w, unsigned group, unsigned element, size_t at, uint32_t length)
{
    if (group != 0x0028)
        return;
    uint64_t *field = element == 0x0010   ? &w->rows
                      : element == 0x0011 ? &w->columns
                      : element == 0x0002 ? &w->samples
                      : element == 0x0100 ? &w->bits
                      : element == 0x0008 ? &w->frames
                                          : NULL;
    if (!field)
        return;
    if (element == 0x0008) { /* IS: decimal text */
        char text[16];
        size_t n = length < sizeof text - 1 ? length : sizeof text - 1;
        memcpy(text, w->data + at, n);
        text[n] = 0;
        *field = strtoull(text, NULL, 10);
    } else if (length >= 2) {
        *field = u16(w, at, w->big);
    }
}

static int walk_items(walk *w, size_t *at, size_t end, int defined, int depth, int pixel_data);

/* Walks data elements from *at to `end` (or, inside an item of undefined length, to its
 * delimiter); depth 0 is the data set itself. Returns 0, 1 on an item delimiter, or -1. */
static int walk_elements(walk *w, size_t *at, size_t end, int depth, int meta)
{
    int big = meta ? 0 : w->big, implicit = meta ? 0 : w->implicit;
    while (*at < end) {
        size_t start = *at;
        if (end - start < 8)
            return fail(w, start, 0, 0, "the file ends inside an element's tag");
        unsigned group = u16(w, start, big), element = u16(w, start + 2, big);
        if (meta && group != 0x0002)
            return 0;          /* the meta group ends */
        if (group == 0xFFFE) { /* an item delimiter ends an item of undefined length */
            *at = start + 8;
            if (element == 0xE00D && depth > 0)
                return 1;
            return fail(w, start, group, element, "an item tag out of place");
        }
        uint32_t length;
        size_t value;
        int sequence = 0;
        if (implicit) {
            length = u32(w, start + 4, big);
            value = start + 8;
            sequence = length == UNDEFINED;
        } else {
            const uint8_t *vr = w->data + start + 4;
            if (long_vr(vr)) {
                if (end - start < 12)
                    return fail(w, start, group, element,
                                "the file ends inside an element's header");
                length = u32(w, start + 8, big);
                value = start + 12;
                sequence = vr[0] == 'S' && vr[1] == 'Q';
            } else {
                length = u16(w, start + 6, big);
                value = start + 8;
            }
        }
        int pixel_data = group == 0x7FE0 && element == 0x0010 && depth == 0;
        w->has_pixels |= pixel_data;
        if (length == UNDEFINED) {
            if (!sequence && !pixel_data && !(w->data[start + 4] == 'U' && !implicit))
                return fail(w, start, group, element, "an undefined length on a value");
            *at = value;
            if (walk_items(w, at, end, 0, depth + 1, pixel_data) != 0)
                return -1;
            continue;
        }
        if (length > end - value)
            return fail(w, start, group, element,
                        "an element longer than what is left of the file");
        if (sequence) {
            size_t inner = value;
            if (walk_items(w, &inner, value + length, 1, depth + 1, 0) != 0)
                return -1;
        } else if (pixel_data && w->bits % 8 == 0) {
            uint64_t frames = w->frames ? w->frames : 1, samples = w->samples ? w->samples : 1;
            uint64_t need = w->rows * w->columns * samples * (w->bits / 8) * frames;
            if (length < need) {
                snprintf(w->why, w->why_size,
                         "its Pixel Data holds %u bytes, less than the %llu of the %llux%llu "
                         "image of %llu bits its header describes",
                         length, (unsigned long long)need, (unsigned long long)w->columns,
                         (unsigned long long)w->rows, (unsigned long long)w->bits);
                return -1;
            }
        } else if (depth == 0) {
            note_value(w, group, element, value, length);
        }
        *at = value + length;
    }
    return 0;
}

/* Walks the items of a sequence (or the fragments of encapsulated Pixel Data) from *at: up to
 * `end` for a `defined` length, else to the sequence delimiter. Returns 0 or -1. */
static int walk_items(walk *w, size_t *at, size_t end, int defined, int depth, int pixel_data)
{
    if (depth > MAX_DEPTH)
        return fail(w, *at, 0, 0, "sequences nested too deep");
    while (*at < end) {
        size_t start = *at;
        if (end - start < 8)
            return fail(w, start, 0xFFFE, 0, "the file ends inside an item's tag");
        unsigned group = u16(w, start, w->big), element = u16(w, start + 2, w->big);
        uint32_t length = u32(w, start + 4, w->big);
        *at = start + 8;
        if (group == 0xFFFE && element == 0xE0DD)
            return 0; /* the sequence delimiter */
        if (group != 0xFFFE || element != 0xE000)
            return fail(w, start, group, element, "an element where an item was expected");
        if (length == UNDEFINED) {
            if (pixel_data)
                return fail(w, start, group, element, "a fragment of undefined length");
            int r = walk_elements(w, at, end, depth, 0);
            if (r < 0)
                return -1;
            if (r == 0)
                return fail(w, *at, group, element, "an item that is never closed");
            continue;
        }
        if (length > end - *at)
            return fail(w, start, group, element, "an item longer than what is left of the file");
        if (!pixel_data) {
            size_t inner = *at;
            if (walk_elements(w, &inner, *at + length, depth, 0) < 0)
                return -1;
        }
        *at += length;
    }
    if (defined)
        return 0; /* its length ends the sequence */
    return fail(w, *at, 0xFFFE, 0xE0DD, "the file ends before the end of a sequence");
}

/* The whole file in memory, or NULL with the reason. */
static uint8_t *read_all(const char *path, size_t *size, char *why, size_t why_size)
{
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        snprintf(why, why_size, "cannot read it: %s", strerror(errno));
        if (fd >= 0)
            close(fd);
        return NULL;
    }
    *size = (size_t)st.st_size;
    uint8_t *data = *size <= MAX_FILE ? malloc(*size ? *size : 1) : NULL;
    size_t got = 0;
    while (data && got < *size) {
        ssize_t n = pread(fd, data + got, *size - got, (off_t)got);
        if (n <= 0)
            break;
        got += (size_t)n;
    }
    close(fd);
    if (!data || got != *size) {
        snprintf(why, why_size, data ? "cannot read it whole" : "out of memory to check it");
        free(data);
        return NULL;
    }
    return data;
}

int ip__dicom_check_file(const char *path, char *why, size_t why_size)
{
    size_t size;
    uint8_t *data = read_all(path, &size, why, why_size);
    if (!data)
        return -1;
    walk w = {data, size, 0, 0, 0, 0, 0, 0, 0, 0, why, why_size};
    size_t at = 132;
    int rc = 0;
    if (size < 132 || memcmp(data + 128, "DICM", 4) != 0) {
        snprintf(why, why_size, "not a DICOM file (no \"DICM\" at byte 128)");
        rc = -1;
    }
    /* the meta group: explicit VR little endian; its Transfer Syntax UID sets the rest */
    size_t meta = at;
    if (rc == 0)
        rc = walk_elements(&w, &at, size, 0, 1) < 0 ? -1 : 0;
    char syntax[65] = "";
    for (size_t p = meta; rc == 0 && p + 8 <= at;) {
        unsigned element = u16(&w, p + 2, 0);
        size_t length = u16(&w, p + 6, 0), value = p + 8;
        if (long_vr(data + p + 4))
            length = u32(&w, p + 8, 0), value = p + 12;
        if (element == 0x0010) {
            size_t n = length < sizeof syntax - 1 ? length : sizeof syntax - 1;
            memcpy(syntax, data + value, n);
            while (n && (syntax[n - 1] == 0 || syntax[n - 1] == ' '))
                n--;
            syntax[n] = 0;
        }
        p = value + length;
    }
    w.implicit = !strcmp(syntax, "1.2.840.10008.1.2");
    w.big = !strcmp(syntax, "1.2.840.10008.1.2.2");
    if (rc == 0 && !syntax[0]) {
        snprintf(why, why_size,
                 "not a well-formed DICOM file: no Transfer Syntax UID in its meta "
                 "header (cut short?)");
        rc = -1;
    }
    /* a deflated data set cannot be walked as it is stored: GDCM inflates it */
    if (rc == 0 && strcmp(syntax, "1.2.840.10008.1.2.1.99") != 0) {
        rc = walk_elements(&w, &at, size, 0, 0) < 0 ? -1 : 0;
        if (rc == 0 && !w.has_pixels) {
            snprintf(why, why_size, "holds no Pixel Data (7FE0,0010): not an image, or cut short");
            rc = -1;
        }
    }
    free(data);
    return rc;
}
