/* SPDX-License-Identifier: BSD-3-Clause */
/* Growable arrays: the one place that works out a larger capacity and reallocates. Internal. */
#ifndef ISOPROP_ARRAY_H
#define ISOPROP_ARRAY_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/status.h"

/* How a capacity grows: doubling, or by half (for arrays that may hold millions of elements,
 * where the slack of doubling costs more than the extra moves). */
typedef enum ip_array_growth {
    IP_ARRAY_DOUBLE = 1,
    IP_ARRAY_HALF = 2
} ip_array_growth;

/*! ip__array_capacity() : the capacity, in elements, that an array of `capacity` elements grows
 *  to so that it holds at least `needed`: `capacity` (or `first` when it is 0) grown by
 *  `growth` until it is enough; `capacity` itself when it already is.
 *  @return : the new capacity, or 0 when `needed` elements of `size` bytes (or the grown
 *  capacity) would not fit in a size_t. */
uint64_t ip__array_capacity(uint64_t capacity, uint64_t needed, uint64_t first, size_t size,
                            ip_array_growth growth);

/*! ip__array_resize() : reallocates the array whose pointer is at `array` (the address of a
 *  pointer of any object type, the pointer NULL or from malloc) to `count` elements of `size`
 *  bytes; the contents up to the smaller size stay.
 *  @return : IP_OK, or IP_ERR_NOMEM (count * size overflows, or no memory) with the array left
 *  as it was. */
ip_status ip__array_resize(void *array, uint64_t count, size_t size);

/*! ip__array_reserve() : makes the array at `array` (as for ip__array_resize) of *capacity
 *  elements of `size` bytes hold at least `needed`, doubling from *capacity (or from `first`
 *  when it is 0); updates *capacity. Does nothing when it already holds `needed`.
 *  @return : IP_OK, or IP_ERR_NOMEM with the array and *capacity left as they were. */
ip_status ip__array_reserve(void *array, uint64_t *capacity, uint64_t needed, size_t size,
                            uint64_t first);

#endif
