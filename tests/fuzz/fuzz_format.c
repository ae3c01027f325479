/* SPDX-License-Identifier: BSD-3-Clause */
/* libFuzzer harness: the brick file header and summary parser on arbitrary bytes.
 * Each input is parsed twice: with checksums (the real path) and without them, so that the
 * structure checks behind the checksums are explored too. Opening must never read out of
 * bounds, and whatever it accepts must be self-consistent. */
#include <stdint.h>
#include <stdlib.h>

#include "format.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_accepted(const ip_layout *l)
{
    /* an accepted layout must describe offsets inside the input: touch its last summary byte */
    if (l->summary_offset + l->summary_size != l->file_size || l->level_count == 0 ||
        l->level_count > IP_MAX_LEVELS || l->levels[l->level_count - 1].brick_count != 1)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ip_layout layout;
    if (ip__format_parse(data, size, "fuzz", 0, &layout, NULL) == IP_OK)
        check_accepted(&layout);
    if (ip__format_parse(data, size, "fuzz", IP_PARSE_SKIP_CHECKSUMS, &layout, NULL) == IP_OK)
        check_accepted(&layout);
    return 0;
}
