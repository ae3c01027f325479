/* SPDX-License-Identifier: BSD-3-Clause */
/* libFuzzer harness: the NRRD and MetaImage header parsers, the TIFF (libtiff) and NIfTI-1/2
 * readers and the plane reader, through the public input API on files, since that is how they
 * meet untrusted bytes.
 *
 * Input layout: byte 0 picks the header kind (0 .nrrd, 1 .nhdr, 2 .mhd, 3 .tif, 4 .nii,
 * 5 .nii.gz, modulo 6); byte 1 is
 * 0 for no companion data file, or 1 + the length of one taken from the end of the input;
 * the bytes in between are the header file. Both files go into a folder made once per
 * process, the companion as "d.raw", so that a header naming "d.raw" (detached NRRD,
 * MetaImage) finds it.
 *
 * Checked: every status is one the API documents and comes with a one-line message; a failed
 * describe leaves its output untouched; an accepted description is in range and names one of
 * the two files; a volume of at most 1 MiB is read plane by plane, and raw-encoded samples
 * must come back exactly as the file holds them, in the host's byte order. */
#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "isoprop/input.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Volumes up to this many bytes are read; larger ones are only described. */
#define READ_LIMIT ((uint64_t)1 << 20)

#define KINDS 6
static const char *const header_names[KINDS] = {"in.nrrd", "in.nhdr", "in.mhd",
                                                "in.tif",  "in.nii",  "in.nii.gz"};

/* The per-process folder, made on the first input and removed at exit. */
static char folder[IP_PATH_MAX];

static void remove_folder(void)
{
    char path[IP_PATH_MAX + 16];
    for (int i = 0; i < KINDS; i++) {
        snprintf(path, sizeof path, "%s/%s", folder, header_names[i]);
        unlink(path);
    }
    snprintf(path, sizeof path, "%s/d.raw", folder);
    unlink(path);
    rmdir(folder);
}

static void make_folder(void)
{
    if (folder[0] != '\0')
        return;
    const char *tmp = getenv("TMPDIR");
    snprintf(folder, sizeof folder, "%s/fuzz_input.XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
    if (!mkdtemp(folder)) {
        perror("fuzz_input: mkdtemp");
        abort();
    }
    atexit(remove_folder);
}

static void write_file(const char *path, const uint8_t *bytes, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(bytes, 1, size, f) != size || fclose(f) != 0) {
        perror(path);
        abort();
    }
}

/* 1 when a line that may name the data file holds a '/': such a name could reach any file on
 * the machine (a huge one, a device), while names without one stay inside the folder. */
static int names_outside_folder(const uint8_t *text, size_t size)
{
    static const char *const keys[] = {"data file", "datafile", "elementdatafile"};
    size_t start = 0;
    while (start < size) {
        const uint8_t *newline = memchr(text + start, '\n', size - start);
        size_t end = newline ? (size_t)(newline - text) : size;
        size_t p = start;
        while (p < end && isspace(text[p]))
            p++;
        for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
            size_t n = strlen(keys[k]);
            if (end - p >= n && strncasecmp((const char *)text + p, keys[k], n) == 0 &&
                memchr(text + p, '/', end - p))
                return 1;
        }
        start = end + 1;
    }
    return 0;
}

static void check_error(ip_status status, const ip_error *err)
{
    if (err->code != status || err->message[0] == '\0' ||
        !memchr(err->message, '\0', sizeof err->message) || strchr(err->message, '\n')) {
        fprintf(stderr, "status %d with code %d and message '%.1023s'\n", (int)status,
                (int)err->code, err->message);
        abort();
    }
}

static void check_desc(const ip_input_desc *d, const char *header, const char *companion)
{
    for (int axis = 0; axis < 3; axis++) {
        if (d->dims[axis] < 2 || d->dims[axis] >= (UINT32_C(1) << 31) ||
            !isfinite(d->spacing[axis]) || d->spacing[axis] <= 0.0)
            abort();
    }
    if (ip_type_size(d->type) == 0 || (d->big_endian != 0 && d->big_endian != 1) ||
        (d->encoding != IP_ENCODING_RAW && d->encoding != IP_ENCODING_GZIP &&
         d->encoding != IP_ENCODING_TIFF) ||
        strcmp(d->path, header) != 0 ||
        (strcmp(d->data_path, header) != 0 && strcmp(d->data_path, companion) != 0))
        abort();
}

/* Raw samples are the file's bytes at data_offset, swapped when their order is not the
 * host's. */
static void check_raw_samples(const ip_input_desc *d, const uint8_t *file, size_t file_size,
                              const unsigned char *samples, uint64_t bytes)
{
    const uint16_t one = 1;
    unsigned char first;
    memcpy(&first, &one, 1);
    int swap = d->big_endian != (first == 0);
    size_t sample = ip_type_size(d->type);
    if (d->data_offset > file_size || file_size - d->data_offset != bytes)
        abort();
    const uint8_t *src = file + d->data_offset;
    for (uint64_t i = 0; i < bytes; i++) {
        uint64_t within = i % sample;
        uint64_t from = swap ? i - within + (sample - 1 - within) : i;
        if (samples[i] != src[from])
            abort();
    }
}

/* Reads every plane of an accepted volume of at most READ_LIMIT bytes. */
static void read_volume(const ip_input_desc *d, const uint8_t *file, size_t file_size)
{
    size_t sample = ip_type_size(d->type);
    uint64_t plane = (uint64_t)d->dims[0] * d->dims[1];
    if (plane > READ_LIMIT || plane * d->dims[2] * sample > READ_LIMIT)
        return;
    uint64_t plane_bytes = plane * sample, bytes = plane_bytes * d->dims[2];
    unsigned char *samples = malloc((size_t)bytes);
    if (!samples)
        abort();
    ip_input_reader *reader = NULL;
    ip_error err;
    ip_error_clear(&err);
    ip_status status = ip_input_open(d, &reader, &err);
    if (status != IP_OK) {
        /* a gzip stream may end inside the header bytes it must skip (.nii.gz) */
        int short_skip = status == IP_ERR_INPUT && d->stream_skip > 0;
        if ((status != IP_ERR_IO && status != IP_ERR_NOMEM && !short_skip) || reader)
            abort();
        check_error(status, &err);
        free(samples);
        return;
    }
    if (ip_input_read_planes(reader, samples, 0, &err) != IP_OK)
        abort();
    uint32_t z = 0;
    for (; z < d->dims[2]; z++) {
        status = ip_input_read_planes(reader, samples + z * plane_bytes, 1, &err);
        if (status != IP_OK)
            break;
    }
    if (status == IP_OK) {
        if (ip_input_read_planes(reader, samples, 1, &err) != IP_ERR_ARGUMENT)
            abort();
        check_error(IP_ERR_ARGUMENT, &err);
        if (d->encoding == IP_ENCODING_RAW)
            check_raw_samples(d, file, file_size, samples, bytes);
    } else {
        if (status != IP_ERR_INPUT && status != IP_ERR_IO && status != IP_ERR_NOMEM)
            abort();
        check_error(status, &err);
        /* describe measured raw data exactly: only a non-finite float may stop the read */
        if (d->encoding == IP_ENCODING_RAW && (d->type != IP_FLOAT32 || status != IP_ERR_INPUT))
            abort();
        ip_status again = ip_input_read_planes(reader, samples + z * plane_bytes, 1, &err);
        if (again != status)
            abort();
        check_error(again, &err);
    }
    ip_input_close(reader);
    free(samples);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2)
        return 0;
    size_t companion_size = data[1] == 0 ? 0 : (size_t)data[1] - 1;
    if (companion_size > size - 2)
        companion_size = size - 2;
    const uint8_t *header = data + 2, *companion = data + size - companion_size;
    size_t header_size = size - 2 - companion_size;
    if (names_outside_folder(header, header_size))
        return 0;

    make_folder();
    char header_path[IP_PATH_MAX], companion_path[IP_PATH_MAX];
    snprintf(header_path, sizeof header_path, "%s/%s", folder, header_names[data[0] % KINDS]);
    snprintf(companion_path, sizeof companion_path, "%s/d.raw", folder);
    write_file(header_path, header, header_size);
    if (data[1] != 0)
        write_file(companion_path, companion, companion_size);

    ip_input_desc desc, untouched;
    ip_error err;
    ip_error_clear(&err);
    memset(&desc, 0xa5, sizeof desc);
    memcpy(&untouched, &desc, sizeof desc);
    ip_status status = ip_input_describe(header_path, NULL, &desc, &err);
    if (status == IP_OK) {
        check_desc(&desc, header_path, companion_path);
        if (strcmp(desc.data_path, header_path) == 0)
            read_volume(&desc, header, header_size);
        else
            read_volume(&desc, companion, companion_size);
    } else {
        /* IP_ERR_NOMEM is not in describe's list, but its header parsers allocate;
         * IP_ERR_UNSUPPORTED is a spacing outside ip_spacing_check()'s bounds, or a TIFF or
         * NIfTI feature that is not read (a sample type, a codec, 4D) */
        if (status != IP_ERR_INPUT && status != IP_ERR_IO && status != IP_ERR_NOMEM &&
            status != IP_ERR_UNSUPPORTED)
            abort();
        check_error(status, &err);
        if (memcmp(&desc, &untouched, sizeof desc) != 0)
            abort();
    }

    unlink(header_path);
    unlink(companion_path);
    return 0;
}
