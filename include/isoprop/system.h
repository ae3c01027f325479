/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: process-level facts the library and the programs share: a monotonic clock, the
 * peak resident set and the thread-count rule. Thread-safe.
 */
#ifndef ISOPROP_SYSTEM_H
#define ISOPROP_SYSTEM_H

#include <stdint.h>

#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/*! ip_now_seconds() : a monotonic clock, in seconds from an arbitrary origin. */
IP_API double ip_now_seconds(void);

/*! ip_peak_rss_bytes() : the peak resident set size of this process (VmHWM), in bytes; 0 when
 *  unknown. */
IP_API uint64_t ip_peak_rss_bytes(void);

/*! ip_rss_bytes() : the resident set size of this process now (VmRSS), in bytes; 0 when
 *  unknown. */
IP_API uint64_t ip_rss_bytes(void);

/* The most threads any run uses. */
#define IP_MAX_THREADS 64

/*! ip_thread_count() : the number of threads a run asking for `requested` uses: `requested`
 *  itself, or every online core when it is 0; at most IP_MAX_THREADS. */
IP_API unsigned ip_thread_count(unsigned requested);

#ifdef __cplusplus
}
#endif
#endif
