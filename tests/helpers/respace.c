/* SPDX-License-Identifier: BSD-3-Clause */
/* respace: a copy of a brick file with another spacing in its header (checksum recomputed),
 * for the end-to-end tests of files whose spacing the programs must refuse to render (isobrick
 * no longer writes them).
 *
 *   respace IN OUT SX,SY,SZ
 *
 * Exit status: 0 done, 1 an I/O error or a file that is not a brick file, 2 a bad command line.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "format.h"

int main(int argc, char **argv)
{
    double spacing[3];
    if (argc != 4 || sscanf(argv[3], "%lf,%lf,%lf", &spacing[0], &spacing[1], &spacing[2]) != 3) {
        fputs("usage: respace IN OUT SX,SY,SZ\n", stderr);
        return 2;
    }
    FILE *in = fopen(argv[1], "rb");
    if (!in || fseek(in, 0, SEEK_END) != 0) {
        fprintf(stderr, "respace: %s: cannot read\n", argv[1]);
        return 1;
    }
    long size = ftell(in);
    unsigned char *file = size > 0 ? malloc((size_t)size) : NULL;
    rewind(in);
    if (!file || fread(file, 1, (size_t)size, in) != (size_t)size) {
        fprintf(stderr, "respace: %s: cannot read\n", argv[1]);
        fclose(in);
        free(file);
        return 1;
    }
    fclose(in);
    ip_layout layout;
    ip_error err;
    if (ip__format_parse(file, (uint64_t)size, argv[1], 0, &layout, &err) != IP_OK) {
        fprintf(stderr, "respace: %s\n", err.message);
        free(file);
        return 1;
    }
    memcpy(layout.spacing, spacing, sizeof spacing);
    ip__format_header_encode(&layout, file);
    FILE *out = fopen(argv[2], "wb");
    int bad = !out || fwrite(file, 1, (size_t)size, out) != (size_t)size;
    if (out)
        bad |= fclose(out) != 0;
    free(file);
    if (bad) {
        fprintf(stderr, "respace: %s: cannot write\n", argv[2]);
        return 1;
    }
    return 0;
}
