/* SPDX-License-Identifier: BSD-3-Clause */
/* Sample types, dimension parsing and status messages. */
#include "check.h"
#include "isoprop/volume.h"

static void test_types(void)
{
    ip_type t;
    CHECK_EQ(ip_type_parse("uint16", &t), IP_OK);
    CHECK_EQ(t, IP_UINT16);
    CHECK_EQ(ip_type_parse("MET_SHORT", &t), IP_OK);
    CHECK_EQ(t, IP_INT16);
    CHECK_EQ(ip_type_parse("float", &t), IP_OK);
    CHECK_EQ(t, IP_FLOAT32);
    CHECK_EQ(ip_type_parse("uint64", &t), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_type_size(IP_UINT8), 1);
    CHECK_EQ(ip_type_size(IP_INT16), 2);
    CHECK_EQ(ip_type_size(IP_FLOAT32), 4);
}

static void test_dims(void)
{
    uint32_t d[3];
    CHECK_EQ(ip_dims_parse("512x512x234", d), IP_OK);
    CHECK_EQ(d[0], 512);
    CHECK_EQ(d[2], 234);
    CHECK_EQ(ip_dims_parse("512x512", d), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_dims_parse("0x5x5", d), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_dims_parse("5x5x5x", d), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_dims_parse("-1x5x5", d), IP_ERR_ARGUMENT);
}

static void test_samples(void)
{
    int16_t s[2] = {-1024, 3071};
    CHECK_EQ(ip_sample_get(s, IP_INT16, 0), -1024.0f);
    CHECK_EQ(ip_sample_get(s, IP_INT16, 1), 3071.0f);
}

static void test_status_messages(void)
{
    for (int code = 0; code >= -11; code--)
        CHECK_NE(strcmp(ip_status_message(code), "unknown error"), 0);
}

static const test_case cases[] = {
    TEST_CASE(test_types),
    TEST_CASE(test_dims),
    TEST_CASE(test_samples),
    TEST_CASE(test_status_messages),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_volume");
}
