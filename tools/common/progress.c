/* SPDX-License-Identifier: BSD-3-Clause */
/* The progress bar on stderr. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tool_common.h"

void tool_progress_start(tool_progress *p, int wanted, const char *force_variable)
{
    const char *force = getenv(force_variable);
    p->show = wanted && ((force && strcmp(force, "1") == 0) || isatty(STDERR_FILENO));
    p->drawn = 0;
    p->start = p->last = ip_now_seconds();
}

double tool_progress_elapsed(const tool_progress *p)
{
    return ip_now_seconds() - p->start;
}

void tool_progress_draw(tool_progress *p, uint64_t done, uint64_t total, const char *unit,
                        const char *detail)
{
    double now = ip_now_seconds();
    if (!p->show || (done < total && now - p->last < 0.2))
        return;
    double elapsed = now - p->start, fraction = total ? (double)done / (double)total : 1;
    if (fraction > 1)
        fraction = 1;
    double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0;
    int width = 30, fill = (int)(fraction * width);
    fprintf(stderr, "\r[%-*.*s] %5.1f%% %llu/%llu %s %s ETA %4.0fs", width, fill,
            "##############################", 100 * fraction, (unsigned long long)done,
            (unsigned long long)total, unit, detail, eta);
    p->drawn = 1;
    p->last = now;
}

void tool_progress_end(tool_progress *p)
{
    if (p->drawn)
        fputc('\n', stderr);
    p->drawn = 0;
}
