/* SPDX-License-Identifier: BSD-3-Clause */
/* Sized structs: the caller's option struct read only as far as it goes. */
#include <string.h>

#include "internal.h"
#include "sized.h"
#include "isoprop/version.h"

/* The size member every sized struct starts with. */
static uint32_t size_of(const void *s)
{
    uint32_t size;
    memcpy(&size, s, sizeof size);
    return size;
}

ip_status ip__sized_in(void *dst, size_t full, const void *src, size_t base, const char *what,
                       ip_error *err)
{
    size_t size = size_of(src);
    if (size == 0)
        size = base;
    if (size < base)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: size %zu is less than the struct's %zu bytes (fill it with its "
                        "ip_*_default() function or IP_SIZED())",
                        what, size, base);
    if (size > full) {
        const unsigned char *extra = (const unsigned char *)src + full;
        for (size_t i = 0; i < size - full; i++)
            if (extra[i] != 0)
                return ip__fail(err, IP_ERR_UNSUPPORTED,
                                "%s: sets fields of a later isoprop than this library (%s): "
                                "%zu bytes against %zu",
                                what, IP__VERSION_STRING, size, full);
        size = full;
    }
    memcpy(dst, src, size);
    uint32_t own = (uint32_t)full;
    memcpy(dst, &own, sizeof own);
    return IP_OK;
}
