/* SPDX-License-Identifier: BSD-3-Clause */
/* The structure of a DICOM Part 10 file, checked before GDCM parses it (dicom_check.h). Only
 * the element framing is read: tags, value representations and lengths, and the few values
 * that size the image (Rows, Columns, Samples per Pixel, Bits Allocated, Number of Frames).
 *
 * The rules are those of PS3.5, read the way GDCM reads them, and narrower where GDCM bends:
 * GDCM takes some malformed files for files of a known broken writer and re-reads them with
 * another interpretation, and several of those paths (and some plain reading paths) end in an
 * assertion that stops the process. So a file passes only when GDCM's own reading of it is
 * the plain one: a meta header that starts with its group length, value representations of the
 * standard, elements in ascending tag order (each once), undefined lengths only where the
 * standard allows them, delimiters where they belong, an offset table first in encapsulated
 * Pixel Data, the values GDCM reads as numbers of the representation its dictionary gives, and
 * none of the few lengths that GDCM rewrites for particular broken writers. */
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "dicom_check.h"

#define MAX_DEPTH 16                   /* nested sequences */
#define UNDEFINED 0xFFFFFFFFu          /* an undefined length */
#define MAX_FILE ((size_t)1 << 31)     /* larger files are not checked (none is a slice) */
#define MAX_INFLATED ((size_t)1 << 29) /* a deflated data set may inflate to this */

#define TAG(group, element) ((uint32_t)(group) << 16 | (uint32_t)(element))
#define PIXEL_DATA TAG(0x7FE0, 0x0010)

/* What the walk needs and finds. */
typedef struct walk {
    const uint8_t *data;
    size_t size;
    /* the image's size: the data set's own values (depth 0), 0 when absent */
    uint64_t rows, columns, samples, bits, frames, bits_stored;
    int has_pixels;        /* the data set holds Pixel Data */
    int encapsulated;      /* ... as fragments (a compressed transfer syntax) */
    uint32_t pixel_length; /* ... else its length */
    size_t pixel_at;       /* where its element starts */
    int has_samples;       /* Samples per Pixel is there */
    /* the data set's even groups 6000-60FE and 5000-50FE: OVERLAY_* bits */
    uint8_t overlays[128], curves[128];
    int in_icon;           /* walking the Icon Image Sequence (0088,0200) of the data set */
    int rle;               /* the transfer syntax is RLE Lossless */
    uint64_t fragments;    /* the data set's Pixel Data fragments, its offset table not counted */
    int bad_rle;           /* one of them does not start with a usable RLE header */
    int bad_first_rle;     /* ... the first one */
    uint32_t rle_segments; /* ... the number of segments the first one's header gives */
    char sop_class[65];    /* the data set's SOP Class UID (0008,0016), "" until walked past */
    int bad_recognition;   /* its Recognition Code (0008,0010) is one GDCM stops on */
    char *why;
    size_t why_size;
} walk;

/* What an overlay (60xx) or curve (50xx) group holds, as GDCM counts them. */
#define GROUP_DATA 1 /* (xxxx,3000), not empty */
#define OVERLAY_ROWS 2
#define OVERLAY_COLUMNS 4
#define OVERLAY_BIT_POSITION 8

/* How the elements being walked are encoded. */
typedef struct coding {
    int implicit, big;
} coding;

/* Where walk_elements() walks, which sets what may end it. */
typedef enum place {
    META,           /* the meta group: ends at the first element of another group */
    DATA_SET,       /* the data set: ends with the file */
    ITEM_DEFINED,   /* an item of defined length: ends with its length */
    ITEM_UNDEFINED, /* an item of undefined length: ends with an item delimiter */
} place;

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

static int fail(walk *w, size_t at, uint32_t tag, const char *what)
{
    snprintf(w->why, w->why_size,
             "not a well-formed DICOM file: %s at byte %zu (element %04X,%04X)", what, at,
             (unsigned)(tag >> 16), (unsigned)(tag & 0xFFFF));
    return -1;
}

/* The value representations of PS3.5: 1 with a 16-bit length, 2 with a 32-bit length after 2
 * reserved bytes, 0 not one of them. (GDCM reads an unknown pair of printable characters as
 * UN, other bytes not at all: neither is taken here.) */
static int vr_form(const uint8_t *vr)
{
    static const char short_vrs[] = "AEASATCSDADSDTFDFLISLOLTPNSHSLSSSTTMUIULUS";
    static const char long_vrs[] = "OBODOFOLOVOWSQSVUCUNURUTUV";
    for (size_t i = 0; i + 1 < sizeof short_vrs; i += 2)
        if (vr[0] == short_vrs[i] && vr[1] == short_vrs[i + 1])
            return 1;
    for (size_t i = 0; i + 1 < sizeof long_vrs; i += 2)
        if (vr[0] == long_vrs[i] && vr[1] == long_vrs[i + 1])
            return 2;
    return 0;
}

static int is_vr(const uint8_t *vr, const char *name)
{
    return vr[0] == name[0] && vr[1] == name[1];
}

/* The elements GDCM reads when it reads an image, with the value representations it takes for
 * them in explicit VR (pairs of letters): those it reads as numbers or text through its
 * Attribute class, which asserts that the file's representation agrees with its dictionary's
 * (or is UN), and the sequences it reads the items of, which it re-parses by guesswork when
 * they are not stored as sequences. Tags of GDCM 3.0's Attribute<> uses and GetValueAsSQ()
 * calls (src/MediaStorageAndFileFormat, DataStructureAndEncodingDefinition,
 * InformationObjectDefinition, Common), representations of its dictionary; overlay and curve
 * groups (60xx, 50xx) as 6000 and 5000. Sorted by tag. */
static const struct typed {
    uint32_t tag;
    const char *vrs;
} typed_elements[] = {
    {TAG(0x0002, 0x0000), "UL"},   {TAG(0x0002, 0x0002), "UI"},   {TAG(0x0002, 0x0003), "UI"},
    {TAG(0x0002, 0x0010), "UI"},   {TAG(0x0004, 0x1130), "CS"},   {TAG(0x0004, 0x1200), "UL"},
    {TAG(0x0004, 0x1202), "UL"},   {TAG(0x0004, 0x1212), "US"},   {TAG(0x0004, 0x1400), "UL"},
    {TAG(0x0004, 0x1410), "US"},   {TAG(0x0004, 0x1420), "UL"},   {TAG(0x0004, 0x1430), "CS"},
    {TAG(0x0004, 0x1500), "CS"},   {TAG(0x0004, 0x1510), "UI"},   {TAG(0x0004, 0x1511), "UI"},
    {TAG(0x0004, 0x1512), "UI"},   {TAG(0x0008, 0x0005), "CS"},   {TAG(0x0008, 0x0008), "CS"},
    {TAG(0x0008, 0x0010), "SH"},   {TAG(0x0008, 0x0016), "UI"},   {TAG(0x0008, 0x0018), "UI"},
    {TAG(0x0008, 0x0020), "DA"},   {TAG(0x0008, 0x0030), "TM"},   {TAG(0x0008, 0x0050), "SH"},
    {TAG(0x0008, 0x0060), "CS"},   {TAG(0x0008, 0x0064), "CS"},   {TAG(0x0008, 0x0070), "LO"},
    {TAG(0x0008, 0x0090), "PN"},   {TAG(0x0008, 0x0100), "SH"},   {TAG(0x0008, 0x0102), "SH"},
    {TAG(0x0008, 0x0103), "SH"},   {TAG(0x0008, 0x0104), "LO"},   {TAG(0x0008, 0x1030), "LO"},
    {TAG(0x0008, 0x1150), "UI"},   {TAG(0x0008, 0x1155), "UI"},   {TAG(0x0008, 0x2111), "ST"},
    {TAG(0x0008, 0x9007), "CS"},   {TAG(0x0010, 0x0010), "PN"},   {TAG(0x0010, 0x0020), "LO"},
    {TAG(0x0010, 0x0030), "DA"},   {TAG(0x0010, 0x0040), "CS"},   {TAG(0x0012, 0x0062), "CS"},
    {TAG(0x0018, 0x0050), "DS"},   {TAG(0x0018, 0x0088), "DS"},   {TAG(0x0018, 0x1063), "DS"},
    {TAG(0x0018, 0x1164), "DS"},   {TAG(0x0018, 0x1182), "ISUL"}, {TAG(0x0018, 0x1310), "US"},
    {TAG(0x0018, 0x1312), "CS"},   {TAG(0x0018, 0x6011), "SQ"},   {TAG(0x0018, 0x602C), "FD"},
    {TAG(0x0018, 0x602E), "FD"},   {TAG(0x0018, 0x9530), "SQ"},   {TAG(0x0020, 0x000D), "UI"},
    {TAG(0x0020, 0x000E), "UI"},   {TAG(0x0020, 0x0010), "SH"},   {TAG(0x0020, 0x0011), "IS"},
    {TAG(0x0020, 0x0013), "IS"},   {TAG(0x0020, 0x0020), "CS"},   {TAG(0x0020, 0x0030), "DS"},
    {TAG(0x0020, 0x0032), "DS"},   {TAG(0x0020, 0x0035), "DS"},   {TAG(0x0020, 0x0037), "DS"},
    {TAG(0x0020, 0x0060), "CS"},   {TAG(0x0020, 0x9113), "SQ"},   {TAG(0x0020, 0x9116), "SQ"},
    {TAG(0x0028, 0x0002), "US"},   {TAG(0x0028, 0x0004), "CS"},   {TAG(0x0028, 0x0005), "US"},
    {TAG(0x0028, 0x0006), "US"},   {TAG(0x0028, 0x0008), "IS"},   {TAG(0x0028, 0x0009), "AT"},
    {TAG(0x0028, 0x0010), "US"},   {TAG(0x0028, 0x0011), "US"},   {TAG(0x0028, 0x0012), "US"},
    {TAG(0x0028, 0x0030), "DS"},   {TAG(0x0028, 0x0034), "IS"},   {TAG(0x0028, 0x0100), "US"},
    {TAG(0x0028, 0x0101), "US"},   {TAG(0x0028, 0x0102), "US"},   {TAG(0x0028, 0x0103), "US"},
    {TAG(0x0028, 0x0106), "SSUS"}, {TAG(0x0028, 0x0107), "SSUS"}, {TAG(0x0028, 0x0120), "SSUS"},
    {TAG(0x0028, 0x1050), "DS"},   {TAG(0x0028, 0x1051), "DS"},   {TAG(0x0028, 0x1052), "DS"},
    {TAG(0x0028, 0x1053), "DS"},   {TAG(0x0028, 0x1054), "LO"},   {TAG(0x0028, 0x1101), "US"},
    {TAG(0x0028, 0x1102), "US"},   {TAG(0x0028, 0x1103), "US"},   {TAG(0x0028, 0x2110), "CS"},
    {TAG(0x0028, 0x2112), "DS"},   {TAG(0x0028, 0x2114), "CS"},   {TAG(0x0028, 0x9110), "SQ"},
    {TAG(0x0028, 0x9145), "SQ"},   {TAG(0x0040, 0x9096), "SQ"},   {TAG(0x0040, 0x9224), "FD"},
    {TAG(0x0040, 0x9225), "FD"},   {TAG(0x0048, 0x0006), "UL"},   {TAG(0x0048, 0x0007), "UL"},
    {TAG(0x0054, 0x0022), "SQ"},   {TAG(0x0062, 0x0004), "US"},   {TAG(0x0062, 0x0005), "LO"},
    {TAG(0x0062, 0x0006), "ST"},   {TAG(0x0062, 0x0008), "CS"},   {TAG(0x0062, 0x0009), "LO"},
    {TAG(0x0062, 0x000C), "US"},   {TAG(0x0062, 0x000D), "US"},   {TAG(0x0066, 0x0001), "UL"},
    {TAG(0x0066, 0x0003), "UL"},   {TAG(0x0066, 0x0004), "LT"},   {TAG(0x0066, 0x0009), "CS"},
    {TAG(0x0066, 0x000A), "FL"},   {TAG(0x0066, 0x000B), "LO"},   {TAG(0x0066, 0x000C), "FL"},
    {TAG(0x0066, 0x000D), "CS"},   {TAG(0x0066, 0x000E), "CS"},   {TAG(0x0066, 0x0010), "CS"},
    {TAG(0x0066, 0x0015), "UL"},   {TAG(0x0066, 0x0017), "FL"},   {TAG(0x0066, 0x0018), "FL"},
    {TAG(0x0066, 0x0019), "FL"},   {TAG(0x0066, 0x001A), "FL"},   {TAG(0x0066, 0x001B), "FL"},
    {TAG(0x0066, 0x001C), "FL"},   {TAG(0x0066, 0x001E), "UL"},   {TAG(0x0066, 0x001F), "US"},
    {TAG(0x0066, 0x0020), "FL"},   {TAG(0x0066, 0x002A), "UL"},   {TAG(0x0066, 0x002C), "UL"},
    {TAG(0x0066, 0x0031), "LO"},   {TAG(0x0066, 0x0036), "LO"},   {TAG(0x0088, 0x0200), "SQ"},
    {TAG(0x0400, 0x0510), "UI"},   {TAG(0x0400, 0x0520), "OB"},   {TAG(0x3004, 0x000C), "DS"},
    {TAG(0x3004, 0x000E), "DS"},   {TAG(0x5000, 0x0005), "US"},   {TAG(0x5000, 0x0010), "US"},
    {TAG(0x5000, 0x0103), "US"},   {TAG(0x5000, 0x0110), "US"},   {TAG(0x5000, 0x0112), "US"},
    {TAG(0x5000, 0x0114), "US"},   {TAG(0x5200, 0x9229), "SQ"},   {TAG(0x5200, 0x9230), "SQ"},
    {TAG(0x5400, 0x1004), "US"},   {TAG(0x6000, 0x0010), "US"},   {TAG(0x6000, 0x0011), "US"},
    {TAG(0x6000, 0x0015), "IS"},   {TAG(0x6000, 0x0022), "LO"},   {TAG(0x6000, 0x0040), "CS"},
    {TAG(0x6000, 0x0050), "SS"},   {TAG(0x6000, 0x0051), "US"},   {TAG(0x6000, 0x0100), "US"},
    {TAG(0x6000, 0x0102), "US"},   {TAG(0x6000, 0x0200), "US"},
};

static int by_tag(const void *key, const void *entry)
{
    uint32_t a = *(const uint32_t *)key, b = ((const struct typed *)entry)->tag;
    return (a > b) - (a < b);
}

/* The entry of `tag` in typed_elements, or NULL. */
static const struct typed *typed_entry(uint32_t tag)
{
    unsigned group = tag >> 16;
    if (((group & 0xFF00) == 0x6000 || (group & 0xFF00) == 0x5000) && !(group & 1))
        tag = (tag & 0xFF00FFFF); /* a repeating group as its first */
    return bsearch(&tag, typed_elements, sizeof typed_elements / sizeof typed_elements[0],
                   sizeof typed_elements[0], by_tag);
}

/* 0, or -1 when element `tag` of representation `vr` (NULL: implicit VR) and `length` is not
 * what GDCM takes for it: a representation of typed_elements (or UN, which it reads as
 * bytes), and no undefined length but on a sequence (UN of undefined length being one). */
static int check_typed(walk *w, size_t at, uint32_t tag, const uint8_t *vr, uint32_t length)
{
    const struct typed *t = typed_entry(tag);
    if (!t)
        return 0;
    int sequence = strcmp(t->vrs, "SQ") == 0;
    if (length == UNDEFINED && !sequence)
        return fail(w, at, tag, "an undefined length on a value");
    if (!vr)
        return 0;
    if (is_vr(vr, "UN") && (!sequence || length == UNDEFINED))
        return 0;
    for (const char *v = t->vrs; *v; v += 2)
        if (is_vr(vr, v))
            return 0;
    char what[64];
    snprintf(what, sizeof what, "a value representation %c%c, not %.2s,",
             vr[0] > 32 && vr[0] < 127 ? vr[0] : '?', vr[1] > 32 && vr[1] < 127 ? vr[1] : '?',
             t->vrs);
    return fail(w, at, tag, what);
}

/* The UI value data[at .. at + length) into out, as GDCM reads it: up to a NUL, at most 64
 * characters, without trailing spaces. */
static void uid_value(const walk *w, size_t at, size_t length, char out[65])
{
    size_t n = 0;
    while (n < length && n < 64 && w->data[at + n] != 0)
        n++;
    memcpy(out, w->data + at, n);
    while (n && out[n - 1] == ' ')
        n--;
    out[n] = '\0';
}

/* The integer value of one of the elements that size the image (US, or IS text for Number of
 * Frames), in the data set itself. */
static void note_value(walk *w, uint32_t tag, size_t at, uint32_t length, int big)
{
    if (tag == TAG(0x0008, 0x0016)) {
        uid_value(w, at, length, w->sop_class);
        return;
    }
    if (tag == TAG(0x0008, 0x0010)) { /* GDCM asserts that it names an ACR-NEMA writer */
        static const char *const codes[] = {"ACR-NEMA", "ACRNEMA", "MIPS 2.0"};
        w->bad_recognition = length > 0;
        for (size_t i = 0; i < 3; i++)
            if (length >= strlen(codes[i]) && memcmp(w->data + at, codes[i], strlen(codes[i])) == 0)
                w->bad_recognition = 0;
        return;
    }
    uint64_t *field = tag == TAG(0x0028, 0x0010)   ? &w->rows
                      : tag == TAG(0x0028, 0x0011) ? &w->columns
                      : tag == TAG(0x0028, 0x0002) ? &w->samples
                      : tag == TAG(0x0028, 0x0100) ? &w->bits
                      : tag == TAG(0x0028, 0x0008) ? &w->frames
                      : tag == TAG(0x0028, 0x0101) ? &w->bits_stored
                                                   : NULL;
    if (!field)
        return;
    w->has_samples |= tag == TAG(0x0028, 0x0002);
    if (tag == TAG(0x0028, 0x0008)) { /* IS: decimal text, read as GDCM does (a negative
                                        * count or none is one frame) */
        uint64_t n = 0;
        size_t i = 0;
        while (i < length && w->data[at + i] == ' ')
            i++;
        if (i < length && w->data[at + i] == '+')
            i++;
        for (; i < length && w->data[at + i] >= '0' && w->data[at + i] <= '9' && n < UINT32_MAX;
             i++)
            n = n * 10 + (w->data[at + i] - '0');
        *field = n;
    } else if (length >= 2) {
        *field = u16(w, at, big);
    }
}

/* 1 when the DS text data[at .. at + length) reads as a number other than 0, the way GDCM
 * reads it (a C++ stream: spaces, then the longest prefix of the form [sign] digits [.
 * digits] [e [sign] digits]; nothing else, no hexadecimal, no "inf"). */
static int nonzero_decimal(const walk *w, size_t at, uint32_t length)
{
    char text[72];
    size_t n = 0, i = 0, digits = 0;
    const uint8_t *p = w->data + at;
    while (i < length && p[i] == ' ')
        i++;
    if (i < length && (p[i] == '+' || p[i] == '-'))
        text[n++] = (char)p[i++];
    for (; i < length && p[i] >= '0' && p[i] <= '9' && n < 64; i++, digits++)
        text[n++] = (char)p[i];
    if (i < length && p[i] == '.' && n < 64)
        for (text[n++] = (char)p[i++]; i < length && p[i] >= '0' && p[i] <= '9' && n < 64;
             i++, digits++)
            text[n++] = (char)p[i];
    if (digits && i + 1 < length && (p[i] == 'e' || p[i] == 'E') && n < 64) {
        size_t mark = n, j = i + 1, exponent = 0;
        text[n++] = 'e';
        if (p[j] == '+' || p[j] == '-')
            text[n++] = (char)p[j++];
        for (; j < length && p[j] >= '0' && p[j] <= '9' && n < 70; j++, exponent++)
            text[n++] = (char)p[j];
        if (!exponent)
            n = mark;
    }
    text[n] = '\0';
    if (!digits)
        return 0;
    double value = strtod(text, NULL);
    return value != 0 && value - value == 0; /* finite */
}

/* Notes an element of an overlay or curve group (even groups 6000-60FE, 5000-50FE) that
 * makes GDCM read the group. */
static void note_group(walk *w, uint32_t tag, uint32_t length)
{
    unsigned group = tag >> 16, element = tag & 0xFFFF;
    if (length == 0 || (group & 1) || ((group & 0xFF00) != 0x6000 && (group & 0xFF00) != 0x5000))
        return;
    uint8_t *flags = (group & 0xFF00) == 0x6000 ? &w->overlays[(group & 0xFF) / 2]
                                                : &w->curves[(group & 0xFF) / 2];
    *flags |= element == 0x3000   ? GROUP_DATA
              : element == 0x0010 ? OVERLAY_ROWS
              : element == 0x0011 ? OVERLAY_COLUMNS
              : element == 0x0102 ? OVERLAY_BIT_POSITION
                                  : 0;
}

/* GDCM reads the overlays (a 60xx group with Overlay Data, or with Overlay Rows, Columns and
 * Bit Position) and the curves (a 50xx group with Curve Data) of a file when it reads its
 * image, and stops the process on many: its overlay reader asserts on any element it does not
 * know (Overlay Activation Layer among them), on a format other than RECT, on more than 16
 * overlays. Neither is needed for the samples: such a file is refused. */
static int check_groups(walk *w)
{
    for (unsigned i = 0; i < 128; i++) {
        const uint8_t o = w->overlays[i],
                      plane = OVERLAY_ROWS | OVERLAY_COLUMNS | OVERLAY_BIT_POSITION;
        const char *what = NULL;
        unsigned group = 0;
        if ((o & GROUP_DATA) || (o & plane) == plane)
            what = "an overlay", group = 0x6000 + 2 * i;
        else if (w->curves[i] & GROUP_DATA)
            what = "a curve", group = 0x5000 + 2 * i;
        if (what) {
            snprintf(w->why, w->why_size,
                     "holds %s (group %04X): overlays and curves are not read (GDCM stops the "
                     "process on some)",
                     what, group);
            return -1;
        }
    }
    return 0;
}

/* Lengths that GDCM replaces by others, taking the file for one of a known broken writer's
 * (GDCM_SUPPORT_BROKEN_IMPLEMENTATION): refused rather than read two ways. */
static int rewritten_length(uint32_t tag, const uint8_t *vr, uint32_t length, coding c)
{
    if (c.implicit)
        return (length == 13 && tag != TAG(0x0008, 0x0070) && tag != TAG(0x0008, 0x0080)) ||
               (length == 0x31f031c && tag == TAG(0x031e, 0x0324));
    return length == 6 && is_vr(vr, "UL") && (tag >> 16) == 0x0009;
}

static int walk_items(walk *w, size_t *at, size_t end, int defined, int depth, int fragments,
                      coding c);

/* The image of an item of the Icon Image Sequence, as GDCM reads it when it reads the file's
 * image: -1 absent, -2 not a 16-bit value. */
typedef struct icon {
    long samples, rows, columns, bits;
    int photometric; /* 0 absent, 1 one GDCM reads, -1 another (empty, PALETTE COLOR, ...) */
} icon;

static void note_icon(const walk *w, icon *i, uint32_t tag, size_t at, uint32_t length, int big)
{
    long *field = tag == TAG(0x0028, 0x0002)   ? &i->samples
                  : tag == TAG(0x0028, 0x0010) ? &i->rows
                  : tag == TAG(0x0028, 0x0011) ? &i->columns
                  : tag == TAG(0x0028, 0x0100) ? &i->bits
                                               : NULL;
    if (field) {
        *field = length == 2 ? (long)u16(w, at, big) : -2;
    } else if (tag == TAG(0x0028, 0x0004)) {
        static const char *const read[] = {"MONOCHROME1", "MONOCHROME2", "RGB"};
        size_t n = length;
        while (n > 0 && (w->data[at + n - 1] == ' ' || w->data[at + n - 1] == 0))
            n--;
        i->photometric = -1;
        for (size_t k = 0; k < sizeof read / sizeof read[0]; k++)
            if (n == strlen(read[k]) && memcmp(w->data + at, read[k], n) == 0)
                i->photometric = 1;
    }
}

/* GDCM reads the first item of the Icon Image Sequence with the file's image, asserting that
 * its samples a pixel are 1, 3 or 4 and that its photometric interpretation is one it knows
 * (and dereferencing an empty one); taken here: 1, 3 or 4 samples, 8 or 16 bits, a size, and
 * MONOCHROME1, MONOCHROME2 or RGB when there is one. */
static int check_icon(walk *w, size_t at, const icon *i)
{
    if ((i->samples == -1 || i->samples == 1 || i->samples == 3 || i->samples == 4) &&
        (i->bits == 8 || i->bits == 16) && i->rows > 0 && i->columns > 0 && i->photometric >= 0)
        return 0;
    return fail(w, at, TAG(0x0088, 0x0200), "an icon image that GDCM cannot read");
}

/* One fragment of the data set's Pixel Data, `length` bytes at `at`: counted, and its RLE
 * header looked at (PS3.5 G.5: the number of segments, then 15 offsets, little endian; the
 * first segment right after the header, each within the fragment, in order). A frame in
 * several fragments has its header in the first. */
static void note_fragment(walk *w, size_t at, uint32_t length)
{
    int bad = length < 64;
    w->fragments++;
    if (!bad) {
        uint32_t segments = u32(w, at, 0);
        if (w->fragments == 1)
            w->rle_segments = segments;
        bad = segments < 1 || segments > 15 || u32(w, at + 4, 0) != 64;
        for (uint32_t i = 1; !bad && i < segments; i++) {
            uint32_t offset = u32(w, at + 4 + 4 * i, 0);
            bad = offset <= u32(w, at + 4 * i, 0) || offset >= length;
        }
    }
    w->bad_rle |= bad;
    if (w->fragments == 1)
        w->bad_first_rle = bad;
}

/* Walks data elements from *at up to `end`, as `where` says; depth 0 is the data set itself.
 * Returns 0, 1 on the item delimiter that closes an item of undefined length, or -1. */
static int walk_elements(walk *w, size_t *at, size_t end, int depth, place where, coding c)
{
    int first = 1, intercept = 0, slope = 0;
    int in_icon = w->in_icon && depth == 1 && (where == ITEM_DEFINED || where == ITEM_UNDEFINED);
    icon image = {-1, -1, -1, -1, 0};
    uint32_t previous = 0;
    w->in_icon = 0; /* not for the sequences in it */
    while (*at < end) {
        size_t start = *at;
        if (end - start < 8)
            return fail(w, start, 0, "the file ends inside an element's tag");
        uint32_t tag = TAG(u16(w, start, c.big), u16(w, start + 2, c.big));
        if (where == META && tag >> 16 != 0x0002)
            return 0; /* the meta group ends */
        if (tag >> 16 == 0xFFFE) {
            if (tag != TAG(0xFFFE, 0xE00D) || where != ITEM_UNDEFINED)
                return fail(w, start, tag, "an item tag out of place");
            if (u32(w, start + 4, c.big) != 0)
                return fail(w, start, tag, "an item delimiter with a length");
            if (intercept && !slope)
                return fail(w, start, tag, "a Rescale Intercept without a Rescale Slope");
            if (in_icon && check_icon(w, start, &image) != 0)
                return -1;
            *at = start + 8;
            return 1;
        }
        if (!first && tag <= previous)
            return fail(w, start, tag, "an element out of ascending tag order (or repeated)");
        first = 0;
        previous = tag;
        const uint8_t *vr = w->data + start + 4;
        uint32_t length;
        size_t value;
        int form = 0;
        if (c.implicit) {
            length = u32(w, start + 4, c.big);
            value = start + 8;
        } else {
            form = vr_form(vr);
            if (form == 0)
                return fail(w, start, tag, "an unknown value representation");
            if (form == 2) {
                if (end - start < 12)
                    return fail(w, start, tag, "the file ends inside an element's header");
                length = u32(w, start + 8, c.big);
                value = start + 12;
            } else {
                length = u16(w, start + 6, c.big);
                value = start + 8;
            }
        }
        if (check_typed(w, start, tag, c.implicit ? NULL : vr, length) != 0)
            return -1;
        int pixel_data = tag == PIXEL_DATA;
        int sequence = !c.implicit && is_vr(vr, "SQ");
        if (pixel_data && !c.implicit && !is_vr(vr, "OB") && !is_vr(vr, "OW"))
            return fail(w, start, tag, "Pixel Data not of value representation OB or OW");
        if (where == META && (sequence || length == UNDEFINED))
            return fail(w, start, tag, "a sequence or an undefined length in the meta header");
        if (rewritten_length(tag, vr, length, c))
            return fail(w, start, tag, "a value length of a known broken writer");
        if (pixel_data && depth == 0) {
            w->has_pixels = 1;
            w->encapsulated = length == UNDEFINED;
            w->pixel_length = length;
            w->pixel_at = start;
        }
        *at = value;
        if (length == UNDEFINED) {
            coding inner = c;
            if (pixel_data) {
                if (walk_items(w, at, end, 0, depth + 1, 1, c) != 0)
                    return -1;
                continue;
            }
            if (!c.implicit && is_vr(vr, "UN"))
                inner.implicit = 1; /* CP-246: its items are in implicit VR */
            else if (!sequence && !c.implicit)
                return fail(w, start, tag, "an undefined length on a value");
            w->in_icon = depth == 0 && tag == TAG(0x0088, 0x0200);
            int r = walk_items(w, at, end, 0, depth + 1, 0, inner);
            w->in_icon = 0;
            if (r != 0)
                return -1;
            continue;
        }
        if (length > end - value)
            return fail(w, start, tag, "an element longer than what is left of the file");
        /* GDCM asserts that a slope it reads is not 0, and reads an intercept without a slope
         * as one over a slope of 0 (for some SOP classes) */
        if (tag == TAG(0x0028, 0x1052))
            intercept = 1;
        if (tag == TAG(0x0028, 0x1053)) {
            if (!nonzero_decimal(w, value, length))
                return fail(w, start, tag, "a Rescale Slope that is not a number other than 0");
            slope = 1;
        }
        w->in_icon = depth == 0 && tag == TAG(0x0088, 0x0200);
        if (sequence) {
            size_t inner = value;
            if (walk_items(w, &inner, value + length, 1, depth + 1, 0, c) != 0)
                return -1;
        } else if (c.implicit && length > 0 && typed_entry(tag) &&
                   strcmp(typed_entry(tag)->vrs, "SQ") == 0) {
            /* GDCM parses the value of a sequence it reads as implicit VR little endian items */
            coding items = {1, 0};
            size_t inner = value;
            if (walk_items(w, &inner, value + length, 1, depth + 1, 0, items) != 0)
                return -1;
        } else if (depth == 0 && where == DATA_SET) {
            note_value(w, tag, value, length, c.big);
            note_group(w, tag, length);
        } else if (in_icon) {
            note_icon(w, &image, tag, value, length, c.big);
        }
        w->in_icon = 0;
        *at = value + length;
    }
    if (intercept && !slope)
        return fail(w, *at, TAG(0x0028, 0x1052), "a Rescale Intercept without a Rescale Slope");
    if (in_icon && check_icon(w, *at, &image) != 0)
        return -1;
    return 0;
}

/* Walks the items of a sequence (or the fragments of encapsulated Pixel Data) from *at: up to
 * `end` for a `defined` length, else to the sequence delimiter. Returns 0 or -1. */
static int walk_items(walk *w, size_t *at, size_t end, int defined, int depth, int fragments,
                      coding c)
{
    if (depth > MAX_DEPTH)
        return fail(w, *at, 0, "sequences nested too deep");
    int first = 1, first_item = 0;
    while (*at < end) {
        size_t start = *at;
        if (end - start < 8)
            return fail(w, start, TAG(0xFFFE, 0), "the file ends inside an item's tag");
        uint32_t tag = TAG(u16(w, start, c.big), u16(w, start + 2, c.big));
        uint32_t length = u32(w, start + 4, c.big);
        *at = start + 8;
        if (tag == TAG(0xFFFE, 0xE0DD)) {
            if (defined)
                return fail(w, start, tag, "a sequence delimiter in a sequence of defined length");
            if (length != 0)
                return fail(w, start, tag, "a sequence delimiter with a length");
            if (fragments && first)
                return fail(w, start, tag, "encapsulated Pixel Data without its offset table");
            return 0;
        }
        if (tag != TAG(0xFFFE, 0xE000))
            return fail(w, start, tag, "an element where an item was expected");
        first_item = first;
        first = 0;
        if (length == UNDEFINED) {
            if (fragments)
                return fail(w, start, tag, "a fragment of undefined length");
            int r = walk_elements(w, at, end, depth, ITEM_UNDEFINED, c);
            if (r < 0)
                return -1;
            if (r == 0)
                return fail(w, *at, tag, "an item that is never closed");
            continue;
        }
        if (length > end - *at)
            return fail(w, start, tag, "an item longer than what is left of the file");
        if (fragments && depth == 1 && !first_item)
            note_fragment(w, *at, length);
        if (!fragments) {
            size_t inner = *at;
            if (walk_elements(w, &inner, *at + length, depth, ITEM_DEFINED, c) < 0)
                return -1;
        }
        *at += length;
    }
    if (defined)
        return 0; /* its length ends the sequence */
    return fail(w, *at, TAG(0xFFFE, 0xE0DD), "the file ends before the end of a sequence");
}

/* The image's size in bytes (Rows x Columns x Samples x Bits Allocated / 8 x Frames, rounded
 * up), UINT64_MAX past that. */
static uint64_t image_bytes(const walk *w)
{
    uint64_t frames = w->frames ? w->frames : 1, samples = w->samples ? w->samples : 1;
    uint64_t bits = w->rows * w->columns; /* each at most 65535 */
    if (__builtin_mul_overflow(bits, samples, &bits) ||
        __builtin_mul_overflow(bits, w->bits, &bits) ||
        __builtin_mul_overflow(bits, frames, &bits) || bits > UINT64_MAX - 7)
        return UINT64_MAX;
    return (bits + 7) / 8;
}

/* RLE Lossless Pixel Data as GDCM's decoder needs it (it divides by the number of segments,
 * and asserts that the samples are 8, 16 or 32 bits, 1 or 3 a pixel, and that the segments add
 * up to the image): one segment for each byte of a pixel, in one fragment a frame. */
static int check_rle(walk *w)
{
    uint64_t samples = w->samples ? w->samples : 1, frames = w->frames ? w->frames : 1;
    const char *what = NULL;
    if ((w->bits != 8 && w->bits != 16 && w->bits != 32) || (samples != 1 && samples != 3))
        what = "RLE Lossless Pixel Data of other than 8, 16 or 32 bits and 1 or 3 samples";
    else if (w->rows == 0 || w->columns == 0)
        what = "RLE Lossless Pixel Data of an empty image";
    else if (w->fragments == 0 || w->bad_first_rle || (frames > 1 && w->bad_rle) ||
             w->rle_segments != samples * (w->bits / 8))
        what = "RLE Lossless Pixel Data without a header that fits its image";
    else if (frames > 1 && w->fragments != frames)
        what = "RLE Lossless Pixel Data with other than one fragment a frame";
    if (!what)
        return 0;
    return fail(w, w->pixel_at, PIXEL_DATA, what);
}

/* An uncompressed Pixel Data must be exactly as long as the image its header describes, with
 * the one byte that pads an odd length to an even one (PS3.5 8.1.1); a longer one describes
 * another image (a size or a sample width that does not match the data), not one to take a
 * part of. RLE Lossless data must be as check_rle() says, and 8-bit samples must store all 8
 * bits. */
static int check_pixels(walk *w)
{
    uint64_t need = image_bytes(w);
    if (w->encapsulated && w->rle && check_rle(w) != 0)
        return -1;
    if (!w->encapsulated && (w->pixel_length < need || w->pixel_length > need + (need & 1))) {
        if (need == UINT64_MAX)
            snprintf(w->why, w->why_size, "its header describes an image too large to hold");
        else
            snprintf(w->why, w->why_size,
                     "its Pixel Data holds %u bytes, %s than the %llu of the %llux%llu image of "
                     "%llu bits its header describes",
                     w->pixel_length, w->pixel_length < need ? "less" : "more",
                     (unsigned long long)need, (unsigned long long)w->columns,
                     (unsigned long long)w->rows, (unsigned long long)w->bits);
        return -1;
    }
    /* GDCM asserts that the samples a pixel are 1, 3 or 4 */
    if (w->has_samples && w->samples != 1 && w->samples != 3 && w->samples != 4) {
        snprintf(w->why, w->why_size, "%llu samples a pixel: not an image GDCM reads",
                 (unsigned long long)w->samples);
        return -1;
    }
    /* GDCM's decoders assert that 8-bit samples store all 8 bits */
    if (w->bits == 8 && w->bits_stored != 0 && w->bits_stored != 8) {
        snprintf(w->why, w->why_size,
                 "8-bit samples of %llu bits stored: only 8 bits stored in 8 are decoded",
                 (unsigned long long)w->bits_stored);
        return -1;
    }
    return 0;
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

/* The raw deflate stream data[0 .. size) inflated (GDCM's reading of a deflated data set), or
 * NULL with the reason. */
static uint8_t *inflate_all(const uint8_t *data, size_t size, size_t *out_size, char *why,
                            size_t why_size)
{
    z_stream z;
    memset(&z, 0, sizeof z);
    if (inflateInit2(&z, -MAX_WBITS) != Z_OK) {
        snprintf(why, why_size, "out of memory to inflate its data set");
        return NULL;
    }
    size_t capacity = size * 4 + 4096, used = 0;
    uint8_t *out = NULL;
    int rc = Z_OK;
    z.next_in = (Bytef *)data;
    while (rc == Z_OK) {
        if (used == capacity || !out) {
            if (out)
                capacity *= 2;
            uint8_t *bigger = capacity <= MAX_INFLATED ? realloc(out, capacity) : NULL;
            if (!bigger)
                break;
            out = bigger;
        }
        size_t in_left = size - (size_t)(z.next_in - data);
        z.avail_in = in_left > UINT32_MAX ? UINT32_MAX : (uInt)in_left;
        z.next_out = out + used;
        z.avail_out = capacity - used > UINT32_MAX ? UINT32_MAX : (uInt)(capacity - used);
        size_t before = z.avail_out;
        rc = inflate(&z, Z_NO_FLUSH);
        used += before - z.avail_out;
        if (rc == Z_BUF_ERROR && z.avail_out > 0)
            break; /* the input ran out */
        if (rc == Z_BUF_ERROR)
            rc = Z_OK;
    }
    inflateEnd(&z);
    if (rc != Z_STREAM_END) {
        snprintf(why, why_size,
                 rc == Z_OK ? "its deflated data set inflates to more than %zu MiB"
                            : "not a well-formed DICOM file: its deflated data set is cut short "
                              "or corrupt",
                 MAX_INFLATED >> 20);
        free(out);
        return NULL;
    }
    *out_size = used;
    return out;
}

/* The value of element (0002,`element`), a UID, of the meta group data[meta .. end): the
 * first, as GDCM reads it (uid_value()); "" when there is none. */
static void meta_uid(const walk *w, size_t meta, size_t end, unsigned element, char out[65])
{
    out[0] = '\0';
    for (size_t p = meta; p + 8 <= end;) {
        size_t length = u16(w, p + 6, 0), value = p + 8;
        if (vr_form(w->data + p + 4) == 2)
            length = u32(w, p + 8, 0), value = p + 12;
        if (u16(w, p + 2, 0) == element) {
            uid_value(w, value, length, out);
            return;
        }
        p = value + length;
    }
}

/* The meta group from byte 132: its group length first, then group 0002 in explicit VR little
 * endian; *at past it. */
static int walk_meta(walk *w, size_t *at, char syntax[65], char media_class[65])
{
    size_t meta = *at;
    if (w->size - meta < 12 || u16(w, meta, 0) != 0x0002 || u16(w, meta + 2, 0) != 0x0000 ||
        !is_vr(w->data + meta + 4, "UL") || u16(w, meta + 6, 0) != 4)
        return fail(w, meta, TAG(0x0002, 0), "no group length first in the meta header");
    coding c = {0, 0};
    if (walk_elements(w, at, w->size, 0, META, c) < 0)
        return -1;
    meta_uid(w, meta, *at, 0x0010, syntax);
    meta_uid(w, meta, *at, 0x0002, media_class);
    if (!syntax[0]) {
        snprintf(w->why, w->why_size,
                 "not a well-formed DICOM file: no Transfer Syntax UID in its meta header (cut "
                 "short?)");
        return -1;
    }
    return 0;
}

/* The data set from `at`, in the encoding `syntax` names (deflated: inflated first). */
static int walk_data_set(walk *w, size_t at, const char *syntax)
{
    static const char *const refused[] = {"1.2.840.113619.5.2", "1.2.840.10008.1.20",
                                          "ImplicitVRBigEndianACRNEMA"};
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++)
        if (strcmp(syntax, refused[i]) == 0) {
            snprintf(w->why, w->why_size,
                     "transfer syntax %s: a private or non-standard encoding, not read", syntax);
            return -1;
        }
    coding c = {strcmp(syntax, "1.2.840.10008.1.2") == 0,
                strcmp(syntax, "1.2.840.10008.1.2.2") == 0};
    int rc;
    w->rle = strcmp(syntax, "1.2.840.10008.1.2.5") == 0;
    if (strcmp(syntax, "1.2.840.10008.1.2.1.99") == 0) {
        size_t size;
        uint8_t *inflated = inflate_all(w->data + at, w->size - at, &size, w->why, w->why_size);
        if (!inflated)
            return -1;
        walk inner = *w;
        inner.data = inflated, inner.size = size;
        size_t start = 0;
        rc = walk_elements(&inner, &start, size, 0, DATA_SET, c);
        *w = inner;
        w->data = NULL, w->size = 0;
        free(inflated);
    } else {
        rc = walk_elements(w, &at, w->size, 0, DATA_SET, c);
    }
    if (rc < 0)
        return -1;
    if (!w->has_pixels) {
        snprintf(w->why, w->why_size,
                 "holds no Pixel Data (7FE0,0010): not an image, or cut short");
        return -1;
    }
    if (w->bad_recognition) {
        snprintf(w->why, w->why_size,
                 "a Recognition Code (0008,0010) other than ACR-NEMA's (GDCM stops the process "
                 "on it)");
        return -1;
    }
    return check_pixels(w) != 0 || check_groups(w) != 0 ? -1 : 0;
}

int ip__dicom_check_object(const char *path, char sop_class[65], char *why, size_t why_size)
{
    size_t size;
    char media_class[65] = "";
    sop_class[0] = '\0';
    uint8_t *data = read_all(path, &size, why, why_size);
    if (!data)
        return -1;
    walk w;
    memset(&w, 0, sizeof w);
    w.data = data, w.size = size, w.why = why, w.why_size = why_size;
    size_t at = 132;
    char syntax[65];
    int rc = -1;
    if (size < 132 || memcmp(data + 128, "DICM", 4) != 0)
        snprintf(why, why_size, "not a DICOM file (no \"DICM\" at byte 128)");
    else if (walk_meta(&w, &at, syntax, media_class) == 0)
        rc = walk_data_set(&w, at, syntax);
    memcpy(sop_class, w.sop_class[0] ? w.sop_class : media_class, 65);
    free(data);
    return rc;
}

int ip__dicom_check_file(const char *path, char *why, size_t why_size)
{
    char sop_class[65];
    return ip__dicom_check_object(path, sop_class, why, why_size);
}
