/* SPDX-License-Identifier: BSD-3-Clause */
/* libFuzzer harness: the Zarr reader's metadata parser (cJSON) and chunk decoder (blosc, zlib,
 * gzip, zstd, lz4, crc32c), directly and through the public input API on a folder.
 *
 * Input layout: byte 0 picks the mode (modulo 4):
 *   0, 1  the rest is a .zarray (0) or zarr.json (1) text, parsed;
 *   2     byte 1 picks the chain (bits 0-2: none, blosc, zlib, gzip, zstd, lz4; bit 3: crc32c
 *         after it), bytes 2-3 the decoded size (little-endian, 1 .. 65535), the rest the
 *         chunk, decoded;
 *   3     byte 1 bit 0 picks v2 (.zarray) or v3 (zarr.json); the rest up to its first NUL is
 *         the metadata, after it the bytes of the chunk at index 0 (written under every key
 *         spelling), described and, up to 1 MiB, read plane by plane.
 * Checked: every failure has a one-line message (the decoder: a reason); a described volume
 * is in range; reading never goes past the buffers (ASan). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "isoprop/input.h"
#include "zarr.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define READ_LIMIT ((uint64_t)1 << 20)

static char folder[IP_PATH_MAX];
static const char *const chunk_names[] = {"0.0.0", "c/0/0/0", "c.0.0.0", "0/0/0"};

static void remove_folder(void)
{
    static const char *const rest[] = {".zarray", "zarr.json", "c/0/0", "c/0", "c", "0/0", "0"};
    char path[IP_PATH_MAX + 16];
    for (size_t i = 0; i < sizeof chunk_names / sizeof chunk_names[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", folder, chunk_names[i]);
        unlink(path);
    }
    for (size_t i = 0; i < sizeof rest / sizeof rest[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", folder, rest[i]);
        if (unlink(path) != 0)
            rmdir(path);
    }
    rmdir(folder);
}

static void make_folder(void)
{
    char path[IP_PATH_MAX + 16];
    if (folder[0] != '\0')
        return;
    const char *tmp = getenv("TMPDIR");
    snprintf(folder, sizeof folder, "%s/fuzz_zarr.XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
    if (!mkdtemp(folder)) {
        perror("fuzz_zarr: mkdtemp");
        abort();
    }
    static const char *const dirs[] = {"c", "c/0", "c/0/0", "0", "0/0"};
    for (size_t i = 0; i < sizeof dirs / sizeof dirs[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", folder, dirs[i]);
        mkdir(path, 0755);
    }
    atexit(remove_folder);
}

static void write_file(const char *name, const uint8_t *bytes, size_t size)
{
    char path[IP_PATH_MAX + 16];
    snprintf(path, sizeof path, "%s/%s", folder, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(bytes, 1, size, f) != size || fclose(f) != 0) {
        perror(path);
        abort();
    }
}

static void check_error(ip_status status, const ip_error *err)
{
    if (status == IP_OK)
        return;
    if (err->message[0] == '\0' || strchr(err->message, '\n'))
        abort();
}

static void parse(const uint8_t *data, size_t size, int version)
{
    char *text = malloc(size + 1);
    zarr_array a;
    ip_error err;
    memcpy(text, data, size);
    text[size] = '\0';
    memset(&a, 0, sizeof a);
    ip_status st = ip__zarr_parse_array("fuzz", text, version, &a, &err);
    check_error(st, &err);
    if (st == IP_OK && (a.ndim < 1 || a.ndim > ZARR_MAX_DIMS || a.item == 0))
        abort();
    free(text);
}

static void decode(const uint8_t *data, size_t size)
{
    static const zarr_codec_id codecs[] = {ZARR_BLOSC, ZARR_ZLIB, ZARR_GZIP, ZARR_ZSTD, ZARR_LZ4};
    if (size < 3)
        return;
    zarr_chain chain = {0, 0, {0}};
    unsigned pick = data[0] & 7u;
    if (pick >= 1 && pick <= 5)
        chain.codecs[chain.count++] = codecs[pick - 1];
    if (data[0] & 8u)
        chain.codecs[chain.count++] = ZARR_CRC32C;
    size_t out = (size_t)data[1] | (size_t)data[2] << 8;
    if (out == 0)
        return;
    unsigned char *dst = malloc(out);
    char why[200] = "";
    if (ip__zarr_decode(&chain, data + 3, size - 3, dst, out, why, sizeof why) != 0 &&
        (why[0] == '\0' || strchr(why, '\n')))
        abort();
    free(dst);
}

static void read_folder(const uint8_t *data, size_t size)
{
    if (size < 1)
        return;
    int v3 = data[0] & 1;
    data++, size--;
    const uint8_t *nul = memchr(data, 0, size);
    size_t meta = nul ? (size_t)(nul - data) : size;
    make_folder();
    remove_folder();
    folder[0] = '\0';
    make_folder();
    write_file(v3 ? "zarr.json" : ".zarray", data, meta);
    if (nul)
        for (size_t i = 0; i < sizeof chunk_names / sizeof chunk_names[0]; i++)
            write_file(chunk_names[i], nul + 1, size - meta - 1);
    ip_input_desc d;
    ip_error err;
    ip_status st = ip_input_describe(folder, NULL, &d, &err);
    check_error(st, &err);
    if (st != IP_OK)
        return;
    uint64_t plane = (uint64_t)d.dims[0] * d.dims[1] * ip_type_size(d.type);
    if (plane * d.dims[2] > READ_LIMIT)
        return;
    ip_input_reader *r;
    st = ip_input_open(&d, &r, &err);
    check_error(st, &err);
    if (st != IP_OK)
        return;
    unsigned char *buf = malloc((size_t)plane);
    for (uint32_t z = 0; z < d.dims[2] && st == IP_OK; z++) {
        st = ip_input_read_planes(r, buf, 1, &err);
        check_error(st, &err);
    }
    free(buf);
    ip_input_close(r);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    switch (data[0] % 4) {
    case 0: parse(data + 1, size - 1, 2); break;
    case 1: parse(data + 1, size - 1, 3); break;
    case 2: decode(data + 1, size - 1); break;
    default: read_folder(data + 1, size - 1); break;
    }
    return 0;
}
