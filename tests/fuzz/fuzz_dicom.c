/* SPDX-License-Identifier: BSD-3-Clause */
/* libFuzzer harness: DICOM series input, whole small series through the public input API, the
 * way isobrick reads them: ip_input_describe() on a folder of 2 to 4 files, then every plane
 * read (ip_input_open, ip_input_read_planes one plane at a time, ip_input_close).
 *
 * Input layout (tests/helpers/make_dicom_corpus.c writes the seeds in it):
 *
 *   byte 0        the number of slices: 2 + byte % 3
 *   byte 1        flags: 1 the slices' names in reverse order (s3, s2, ... for slices 0, 1, ...),
 *                 2 the template also as "DICOMDIR" (an index: not a slice), 4 a hidden file
 *                 ".partial" (skipped), 8 a text file "x_notes.txt" (not DICOM: refused)
 *   bytes 2, 3    the template's length T, little endian (cut to what the input holds)
 *   T bytes       the template: one DICOM file, the starting point of every slice
 *   then edits, to the end of the input, each:
 *                 byte: the slice it applies to (modulo the count),
 *                 u16 offset, u16 bytes removed, u16 bytes inserted (little endian), then the
 *                 inserted bytes; the edit replaces the removed bytes from offset (both cut to
 *                 the slice's current size) with the inserted ones. Edits of a slice apply in
 *                 input order.
 *
 * So a mutation of the template reaches every slice at once (Rows, Bits Allocated, the
 * transfer syntax, the pixel data of the whole series), while the edits make slices differ
 * (positions, one slice's size or bit layout, a cut, a longer or shorter Pixel Data; an edit at
 * offset 0 that removes everything holds a whole file of its own, another transfer syntax).
 * The files go into a folder made once per process (removed at exit), emptied after each input.
 *
 * Checked: describe and every read return a status the API documents, with a one-line message
 * that names the folder (or a file in it); a failed describe leaves its output untouched; an
 * accepted series is a DICOM description of as many planes as the slices it read (those of the
 * folder but the objects skipped by their SOP class: slices read and objects skipped together
 * no more than the files written), of a DICOM sample type, with finite positive spacing; a volume of at most READ_LIMIT bytes is read plane by plane, and
 * after an error the reader repeats it. Crashes, sanitizer reports, leaks, hangs and anything
 * the DICOM library throws or asserts that reaches the process are failures.
 *
 * With FUZZ_DICOM_VERBOSE set, each input's outcome is printed on stderr (to see what the seeds
 * and the inputs found reach: fuzz_dicom FILE...). */
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "isoprop/input.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Volumes up to this many bytes are read; larger ones (a compressed slice may claim any size)
 * are only described. */
#define READ_LIMIT ((uint64_t)1 << 20)
#define MAX_SLICES 4

/* The per-process folder, made on the first input and removed at exit. */
static char folder[IP_PATH_MAX];

/* Removes every file of the folder (the names vary from input to input). */
static void empty_folder(void)
{
    DIR *dir = opendir(folder);
    if (!dir)
        return;
    struct dirent *entry;
    char path[IP_PATH_MAX + 260];
    while ((entry = readdir(dir)) != NULL) {
        if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", folder, entry->d_name);
        unlink(path);
    }
    closedir(dir);
}

static void remove_folder(void)
{
    empty_folder();
    rmdir(folder);
}

static void make_folder(void)
{
    if (folder[0] != '\0')
        return;
    const char *tmp = getenv("TMPDIR");
    snprintf(folder, sizeof folder, "%s/fuzz_dicom.XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
    if (!mkdtemp(folder)) {
        perror("fuzz_dicom: mkdtemp");
        abort();
    }
    atexit(remove_folder);
}

static void write_file(const char *name, const uint8_t *bytes, size_t size)
{
    char path[IP_PATH_MAX + 260];
    snprintf(path, sizeof path, "%s/%s", folder, name);
    FILE *f = fopen(path, "wb");
    if (!f || (size && fwrite(bytes, 1, size, f) != size) || fclose(f) != 0) {
        perror(path);
        abort();
    }
}

static int verbose = -1;

static void say(const char *what, ip_status status, const char *message)
{
    if (verbose < 0)
        verbose = getenv("FUZZ_DICOM_VERBOSE") != NULL;
    if (verbose)
        fprintf(stderr, "fuzz_dicom: %s: %s\n", what, status == IP_OK ? "ok" : message);
}

static unsigned get16(const uint8_t *p)
{
    return (unsigned)p[0] | (unsigned)p[1] << 8;
}

/* A growable byte string: one slice. */
typedef struct slice {
    uint8_t *bytes;
    size_t size;
} slice;

/* Replaces `removed` bytes at `offset` (both cut to the slice) with `inserted` bytes. */
static void splice(slice *s, size_t offset, size_t removed, const uint8_t *inserted,
                   size_t inserted_size)
{
    if (offset > s->size)
        offset = s->size;
    if (removed > s->size - offset)
        removed = s->size - offset;
    size_t size = s->size - removed + inserted_size;
    uint8_t *bytes = malloc(size ? size : 1);
    if (!bytes)
        abort();
    memcpy(bytes, s->bytes, offset);
    if (inserted_size)
        memcpy(bytes + offset, inserted, inserted_size);
    memcpy(bytes + offset + inserted_size, s->bytes + offset + removed, s->size - offset - removed);
    free(s->bytes);
    s->bytes = bytes;
    s->size = size;
}

/* Every status comes with its own code and a one-line message that names the folder. */
static void check_error(ip_status status, const ip_error *err)
{
    if (err->code != status || err->message[0] == '\0' ||
        !memchr(err->message, '\0', sizeof err->message) || strchr(err->message, '\n') ||
        strncmp(err->message, folder, strlen(folder)) != 0) {
        fprintf(stderr, "status %d with code %d and message '%.1023s'\n", (int)status,
                (int)err->code, err->message);
        abort();
    }
}

/* `files`: the DICOM files written (the slices, and a DICOMDIR when there is one). */
static void check_desc(const ip_input_desc *d, unsigned files)
{
    for (int axis = 0; axis < 3; axis++)
        if (d->dims[axis] < 2 || !isfinite(d->spacing[axis]) || d->spacing[axis] <= 0.0)
            abort();
    if (d->dims[2] != d->source_slices || d->source_slices + d->skipped_objects > files ||
        d->series_count != 1 || d->encoding != IP_ENCODING_DICOM || d->big_endian != 0 ||
        (d->type != IP_UINT8 && d->type != IP_UINT16 && d->type != IP_INT16) ||
        strcmp(d->path, folder) != 0 || strcmp(d->data_path, folder) != 0)
        abort();
}

/* Reads every plane of an accepted series of at most READ_LIMIT bytes, one at a time. */
static void read_series(const ip_input_desc *d)
{
    uint64_t plane = (uint64_t)d->dims[0] * d->dims[1] * ip_type_size(d->type);
    if (plane * d->dims[2] > READ_LIMIT)
        return;
    unsigned char *samples = malloc((size_t)(plane * d->dims[2]));
    if (!samples)
        abort();
    ip_input_reader *reader = NULL;
    ip_error err;
    ip_error_clear(&err);
    ip_status status = ip_input_open(d, &reader, &err);
    if (status != IP_OK) {
        /* the folder is read again on opening: the same files, so the same verdict */
        fprintf(stderr, "open after describe: %s\n", err.message);
        abort();
    }
    uint32_t z = 0;
    for (; z < d->dims[2]; z++) {
        status = ip_input_read_planes(reader, samples + z * plane, 1, &err);
        if (status != IP_OK)
            break;
    }
    say("read", status, err.message);
    if (status == IP_OK) {
        if (ip_input_read_planes(reader, samples, 1, &err) != IP_ERR_ARGUMENT)
            abort();
    } else {
        if (status != IP_ERR_INPUT && status != IP_ERR_IO && status != IP_ERR_NOMEM)
            abort();
        check_error(status, &err);
        ip_status again = ip_input_read_planes(reader, samples + z * plane, 1, &err);
        if (again != status)
            abort();
        check_error(again, &err);
    }
    ip_input_close(reader);
    free(samples);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 4)
        return 0;
    unsigned count = 2 + data[0] % 3, flags = data[1];
    size_t template_size = get16(data + 2), at = 4;
    if (template_size > size - at)
        template_size = size - at;
    slice slices[MAX_SLICES];
    for (unsigned k = 0; k < count; k++) {
        slices[k].bytes = malloc(template_size ? template_size : 1);
        if (!slices[k].bytes)
            abort();
        memcpy(slices[k].bytes, data + at, template_size);
        slices[k].size = template_size;
    }
    at += template_size;
    while (size - at >= 7) {
        slice *s = &slices[data[at] % count];
        size_t offset = get16(data + at + 1), removed = get16(data + at + 3);
        size_t inserted = get16(data + at + 5);
        at += 7;
        if (inserted > size - at)
            inserted = size - at;
        splice(s, offset, removed, data + at, inserted);
        at += inserted;
    }

    make_folder();
    for (unsigned k = 0; k < count; k++) {
        char name[16];
        snprintf(name, sizeof name, "s%u", flags & 1 ? count - 1 - k : k);
        write_file(name, slices[k].bytes, slices[k].size);
        free(slices[k].bytes);
    }
    if (flags & 2)
        write_file("DICOMDIR", data + 4, template_size);
    if (flags & 4)
        write_file(".partial", data + 4, template_size / 2);
    if (flags & 8)
        write_file("x_notes.txt", (const uint8_t *)"scanned on Tuesday\n", 19);

    ip_input_desc desc, untouched;
    ip_error err;
    ip_error_clear(&err);
    memset(&desc, 0xa5, sizeof desc);
    memcpy(&untouched, &desc, sizeof desc);
    ip_status status = ip_input_describe(folder, NULL, &desc, &err);
    say("describe", status, err.message);
    if (status == IP_OK) {
        check_desc(&desc, count + (flags & 2 ? 1 : 0));
        read_series(&desc);
    } else {
        /* IP_ERR_UNSUPPORTED: a transfer syntax, sample type or photometric interpretation
         * that is not read, or a spacing outside ip_spacing_check()'s bounds */
        if (status != IP_ERR_INPUT && status != IP_ERR_IO && status != IP_ERR_NOMEM &&
            status != IP_ERR_UNSUPPORTED)
            abort();
        check_error(status, &err);
        if (memcmp(&desc, &untouched, sizeof desc) != 0)
            abort();
    }
    empty_folder();
    return 0;
}
