/* SPDX-License-Identifier: BSD-3-Clause */
/* Sized structs (include/isoprop/status.h): the public option structs that start with their
 * size, read from the caller's memory only as far as the caller's struct goes. */
#ifndef ISOPROP_SIZED_H
#define ISOPROP_SIZED_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/status.h"

/* IP__SIZE_UPTO(type, field): the bytes of `type` up to and including `field`: the struct's
 * size in the version whose last field that was. */
#define IP__SIZE_UPTO(type, field) (offsetof(type, field) + sizeof(((type *)0)->field))

/* ip__sized_in() : takes the caller's struct `src` (its first member its size in bytes; 0:
 * `base`, the size in 0.2.0) into the library's own `dst` of `full` bytes, which holds the
 * defaults: the fields the caller's struct has replace them. dst's size becomes `full`.
 * IP_ERR_ARGUMENT (naming `what`) for a size under `base`; IP_ERR_UNSUPPORTED for a larger
 * struct than this library's whose extra bytes are not all zero. */
ip_status ip__sized_in(void *dst, size_t full, const void *src, size_t base, const char *what,
                       ip_error *err);

#endif
