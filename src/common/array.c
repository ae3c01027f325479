/* SPDX-License-Identifier: BSD-3-Clause */
/* Growable arrays. */
#include <stdlib.h>
#include <string.h>

#include "array.h"

uint64_t ip__array_capacity(uint64_t capacity, uint64_t needed, uint64_t first, size_t size,
                            ip_array_growth growth)
{
    uint64_t limit = (uint64_t)(SIZE_MAX / (size ? size : 1));
    if (needed <= capacity)
        return capacity;
    if (needed > limit)
        return 0;
    uint64_t cap = capacity ? capacity : first ? first : 1;
    while (cap < needed) {
        uint64_t step = cap / (uint64_t)growth ? cap / (uint64_t)growth : 1;
        cap = cap <= limit - step ? cap + step : limit;
    }
    return cap;
}

ip_status ip__array_resize(void *array, uint64_t count, size_t size)
{
    void *old;
    /* `array` points to a pointer of some object type: copy its bytes, not its lvalue */
    memcpy(&old, array, sizeof old);
    if (size && count > SIZE_MAX / size)
        return IP_ERR_NOMEM;
    void *grown = realloc(old, (size_t)count * size);
    if (!grown)
        return IP_ERR_NOMEM;
    memcpy(array, &grown, sizeof grown);
    return IP_OK;
}

ip_status ip__array_reserve(void *array, uint64_t *capacity, uint64_t needed, size_t size,
                            uint64_t first)
{
    if (needed <= *capacity)
        return IP_OK;
    uint64_t cap = ip__array_capacity(*capacity, needed, first, size, IP_ARRAY_DOUBLE);
    if (cap == 0)
        return IP_ERR_NOMEM;
    ip_status st = ip__array_resize(array, cap, size);
    if (st == IP_OK)
        *capacity = cap;
    return st;
}
