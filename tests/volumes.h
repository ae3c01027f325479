/* SPDX-License-Identifier: BSD-3-Clause */
/* Test volumes on disk: a generated field written as a raw file, a raw file bricked. */
#ifndef ISOPROP_TEST_VOLUMES_H
#define ISOPROP_TEST_VOLUMES_H

#include "check.h"
#include "isoprop/bricker.h"
#include "isoprop/generate.h"

/* Writes the field of `params` to dir/NAME_XxYxZ_TYPE.raw; its path into raw[size]. */
static inline void test_generate_raw(const char *dir, const char *name, const ip_gen_params *params,
                                     char *raw, size_t size)
{
    char file[256];
    ip_error err;
    REQUIRE(ip_raw_file_name(file, sizeof file, name, params->dims, params->type) == IP_OK);
    snprintf(raw, size, "%s/%s", dir, file);
    REQUIRE(ip_generate_write(params, raw, 1, &err) == IP_OK);
}

/* Bricks the raw file `raw` (its name says dims and type) into `ibv`, replacing it, with two
 * threads: the threaded bricker on any machine. */
static inline void test_brick_raw(const char *raw, const char *ibv, uint32_t brick_edge,
                                  uint32_t subblock_edge)
{
    ip_input_desc desc;
    ip_bricker_options options;
    ip_error err;
    REQUIRE(ip_input_describe(raw, NULL, &desc, &err) == IP_OK);
    ip_bricker_options_default(&options);
    options.brick_edge = brick_edge;
    options.subblock_edge = subblock_edge;
    options.force = 1;
    options.threads = 2;
    REQUIRE(ip_bricker_run(&desc, ibv, &options, NULL, &err) == IP_OK);
}

#endif
