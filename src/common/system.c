/* SPDX-License-Identifier: BSD-3-Clause */
/* Process-level facts: a monotonic clock, the peak resident set, the number of cores. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include "internal.h"
#include "isoprop/system.h"

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23 /* Linux 5.14 */
#endif

/* The number after `field` on its line of the text file `path`; 0 when unknown. */
static uint64_t proc_field(const char *path, const char *field)
{
    FILE *f = fopen(path, "r");
    char line[256];
    uint64_t value = 0;
    size_t n = strlen(field);
    if (!f)
        return 0;
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, field, n) == 0) {
            value = strtoull(line + n, NULL, 10);
            break;
        }
    }
    fclose(f);
    return value;
}

/* A field of /proc/self/status given in KiB ("VmRSS:", "VmHWM:"), in bytes; 0 when unknown. */
static uint64_t status_bytes(const char *field)
{
    return proc_field("/proc/self/status", field) * 1024u;
}

uint64_t ip__process_read_bytes(void)
{
    return proc_field("/proc/self/io", "read_bytes:");
}

uint64_t ip_peak_rss_bytes(void)
{
    return status_bytes("VmHWM:");
}

uint64_t ip_rss_bytes(void)
{
    return status_bytes("VmRSS:");
}

void ip__memory_populate(void *p, size_t bytes)
{
    long size = sysconf(_SC_PAGESIZE);
    size_t page = size > 0 ? (size_t)size : 4096;
    uintptr_t first = ((uintptr_t)p + page - 1) & ~(uintptr_t)(page - 1);
    uintptr_t end = ((uintptr_t)p + bytes) & ~(uintptr_t)(page - 1);
    if (p && end > first)
        (void)madvise((void *)first, end - first, MADV_POPULATE_WRITE);
}

double ip_now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

unsigned ip_thread_count(unsigned requested)
{
    if (requested > 0)
        return requested > IP_MAX_THREADS ? IP_MAX_THREADS : requested;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1u : n > IP_MAX_THREADS ? IP_MAX_THREADS : (unsigned)n;
}
