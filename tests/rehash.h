/* SPDX-License-Identifier: BSD-3-Clause */
/* For tests, fuzzers and tests/helpers/corrupt.c: recomputes every checksum of a brick file
 * image in memory from the header's own fields (docs/format.md): each payload's in its
 * directory entry, the summary section's, the header's. Trusts nothing: every offset is
 * bounds-checked against the image and what does not fit is left alone. A mutated file then
 * passes its checksums, so that what lies behind them is what gets tested. */
#ifndef ISOPROP_TESTS_REHASH_H
#define ISOPROP_TESTS_REHASH_H

#include <stddef.h>
#include <stdint.h>

#include "format.h"
#include "format_offsets.h"
#include "internal.h"

static inline void test_rehash(unsigned char *file, uint64_t size)
{
    if (size < IP_HEADER_SIZE)
        return;
    uint32_t level_count = ip__load_u32le(file + IP_HDR_LEVEL_COUNT);
    uint64_t brick_count = ip__load_u64le(file + IP_HDR_BRICK_COUNT);
    uint64_t summary_offset = ip__load_u64le(file + IP_HDR_SUMMARY_OFFSET);
    uint64_t summary_size = ip__load_u64le(file + IP_HDR_SUMMARY_SIZE);
    if (summary_offset <= size && summary_size <= size - summary_offset) {
        uint64_t directory = (uint64_t)level_count * IP_LEVEL_ENTRY_SIZE;
        uint64_t entries =
            directory <= summary_size ? (summary_size - directory) / IP_DIRECTORY_ENTRY_SIZE : 0;
        for (uint64_t g = 0; g < brick_count && g < entries; g++) {
            unsigned char *e = file + summary_offset + directory + g * IP_DIRECTORY_ENTRY_SIZE;
            uint64_t offset = ip__load_u64le(e + IP_DIR_OFFSET);
            uint32_t stored = ip__load_u32le(e + IP_DIR_STORED_SIZE);
            if (stored > 0 && offset <= size && stored <= size - offset)
                ip__store_u64le(e + IP_DIR_CHECKSUM, ip__format_checksum(file + offset, stored));
        }
        ip__store_u64le(file + IP_HDR_SUMMARY_CHECKSUM,
                        ip__format_checksum(file + summary_offset, summary_size));
    }
    ip__store_u64le(file + IP_HDR_CHECKSUM, ip__format_checksum(file, IP_HDR_CHECKSUM));
}

#endif
