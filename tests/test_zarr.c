/* SPDX-License-Identifier: BSD-3-Clause */
/* The Zarr reader's pieces (src/input_formats/zarr*.c): CRC-32C against RFC 3720's vectors,
 * the metadata parser's types and refusals, the chunk decoder's length checks, and the types
 * that are converted (int8 to int16, 32-bit integers to float32) end to end. The formats
 * themselves, against a raw volume: tests/tools/zarr.sh. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "isoprop/input.h"
#include "zarr.h"

static void test_crc32c_rfc3720(void)
{
    unsigned char b[32];
    memset(b, 0, sizeof b);
    CHECK_EQ(ip__crc32c(b, 32), 0x8A9136AAu);
    memset(b, 0xFF, sizeof b);
    CHECK_EQ(ip__crc32c(b, 32), 0x62A8AB43u);
    for (int i = 0; i < 32; i++)
        b[i] = (unsigned char)i;
    CHECK_EQ(ip__crc32c(b, 32), 0x46DD794Eu);
    for (int i = 0; i < 32; i++)
        b[i] = (unsigned char)(31 - i);
    CHECK_EQ(ip__crc32c(b, 32), 0x113FDB5Cu);
    CHECK_EQ(ip__crc32c((const unsigned char *)"123456789", 9), 0xE3069283u);
}

static ip_status parse_v2(const char *dtype, const char *extra, zarr_array *a, ip_error *err)
{
    char text[512];
    snprintf(text, sizeof text,
             "{\"zarr_format\": 2, \"shape\": [4, 3, 2], \"chunks\": [4, 3, 2], \"dtype\": "
             "\"%s\", \"compressor\": null, \"fill_value\": 0%s}",
             dtype, extra);
    memset(a, 0, sizeof *a);
    return ip__zarr_parse_array("a/.zarray", text, 2, a, err);
}

static void test_types_and_refusals(void)
{
    zarr_array a;
    ip_error err;
    CHECK_EQ(parse_v2("|i1", "", &a, &err), IP_OK);
    CHECK_EQ(a.type, IP_INT16);
    CHECK_EQ(parse_v2(">u4", "", &a, &err), IP_OK);
    CHECK_EQ(a.type, IP_FLOAT32);
    CHECK_EQ(a.chain.big_endian, 1);
    CHECK_EQ(parse_v2("<u2", ", \"dimension_separator\": \"/\"", &a, &err), IP_OK);
    CHECK_EQ(a.separator, '/');
    CHECK_EQ(parse_v2("<f8", "", &a, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "a/.zarray: data type <f8 is not read");
    CHECK_EQ(
        ip__zarr_parse_array("a/.zarray",
                             "{\"zarr_format\": 2, \"shape\": [4, 3, 2], \"chunks\": [4, 3, 2], "
                             "\"dtype\": \"|u1\", \"fill_value\": -3}",
                             2, &a, &err),
        IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "a/.zarray: 'fill_value' -3 is not a value of the data type");
    CHECK_EQ(parse_v2("<u2", ", \"order\": \"F\"", &a, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "order \"F\"");
    CHECK_EQ(ip__zarr_parse_array("a/.zarray",
                                  "{\"zarr_format\": 2, \"shape\": [4096, 4096, 4096], "
                                  "\"chunks\": [2048, 2048, 2048], \"dtype\": \"<u2\"}",
                                  2, &a, &err),
             IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "a/.zarray: a chunk of more than 1 GiB is not read");
    CHECK_EQ(ip__zarr_parse_array("a/zarr.json", "{\"zarr_format\": 3,", 3, &a, &err),
             IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "a/zarr.json: not JSON");
}

static void test_decode_lengths(void)
{
    zarr_chain lz4 = {0, 1, {ZARR_LZ4}}, none = {0, 0, {0}}, crc = {0, 1, {ZARR_CRC32C}};
    unsigned char src[16] = {8, 0, 0, 0}, dst[16];
    char why[200];
    CHECK_EQ(ip__zarr_decode(&lz4, src, 4, dst, 16, why, sizeof why), -1);
    CHECK_CONTAINS(why, "lz4: decodes to 8 bytes, not the chunk's 16");
    CHECK_EQ(ip__zarr_decode(&lz4, src, 3, dst, 8, why, sizeof why), -1);
    CHECK_CONTAINS(why, "under the 4-byte size header");
    CHECK_EQ(ip__zarr_decode(&none, src, 15, dst, 16, why, sizeof why), -1);
    CHECK_EQ(ip__zarr_decode(&none, src, 16, dst, 16, why, sizeof why), 0);
    uint32_t c = ip__crc32c(src, 12);
    for (int k = 0; k < 4; k++)
        src[12 + k] = (unsigned char)(c >> (8 * k));
    CHECK_EQ(ip__zarr_decode(&crc, src, 16, dst, 12, why, sizeof why), 0);
    src[0] ^= 1;
    CHECK_EQ(ip__zarr_decode(&crc, src, 16, dst, 12, why, sizeof why), -1);
    CHECK_CONTAINS(why, "crc32c: checksum mismatch");
}

/* A 2x3x4 (x, y, z) uncompressed v2 array of `dtype` holding `bytes` in one chunk. */
static void write_array(const char *dir, const char *dtype, const void *bytes, size_t size)
{
    char path[4096];
    mkdir(dir, 0755);
    snprintf(path, sizeof path, "%s/.zarray", dir);
    FILE *f = fopen(path, "w");
    REQUIRE(f != NULL);
    fprintf(f,
            "{\"zarr_format\": 2, \"shape\": [4, 3, 2], \"chunks\": [4, 3, 2], \"dtype\": "
            "\"%s\", \"compressor\": null, \"fill_value\": 0, \"order\": \"C\", \"filters\": "
            "null}",
            dtype);
    fclose(f);
    snprintf(path, sizeof path, "%s/0.0.0", dir);
    f = fopen(path, "wb");
    REQUIRE(f != NULL);
    fwrite(bytes, 1, size, f);
    fclose(f);
}

static ip_status read_all(const char *dir, ip_input_desc *d, void *dst, ip_error *err)
{
    ip_input_reader *r;
    ip_status st = ip_input_describe(dir, NULL, d, err);
    if (st == IP_OK && (st = ip_input_open(d, &r, err)) == IP_OK) {
        st = ip_input_read_planes(r, dst, 4, err);
        ip_input_close(r);
    }
    return st;
}

static void test_converted_types(void)
{
    char dir[4200];
    const char *tmp = test_tmp_dir("test_zarr");
    int8_t i8[24];
    uint32_t u32[24];
    int16_t got16[24];
    float gotf[24];
    ip_input_desc d;
    ip_error err;
    for (int i = 0; i < 24; i++) {
        i8[i] = (int8_t)(i * 11 - 128);
        u32[i] = (uint32_t)i * 700000u; /* up to 16.1 million: float32 holds them exactly */
    }
    snprintf(dir, sizeof dir, "%s/i8", tmp);
    write_array(dir, "|i1", i8, sizeof i8);
    CHECK_EQ(read_all(dir, &d, got16, &err), IP_OK);
    CHECK_EQ(d.type, IP_INT16);
    int same = 1;
    for (int i = 0; i < 24; i++)
        same &= got16[i] == i8[i];
    CHECK(same);
    snprintf(dir, sizeof dir, "%s/u4", tmp);
    write_array(dir, "<u4", u32, sizeof u32);
    CHECK_EQ(read_all(dir, &d, gotf, &err), IP_OK);
    CHECK_EQ(d.type, IP_FLOAT32);
    same = 1;
    for (int i = 0; i < 24; i++)
        same &= gotf[i] == (float)u32[i];
    CHECK(same);
    u32[5] = (1u << 24) + 1;
    snprintf(dir, sizeof dir, "%s/u4big", tmp);
    write_array(dir, "<u4", u32, sizeof u32);
    CHECK_EQ(read_all(dir, &d, gotf, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "u4big: a uint32 sample in (x,y,z) = (0..1,2,0) is past 2^24");
}

static const test_case cases[] = {
    TEST_CASE(test_crc32c_rfc3720),
    TEST_CASE(test_types_and_refusals),
    TEST_CASE(test_decode_lengths),
    TEST_CASE(test_converted_types),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_zarr");
}
