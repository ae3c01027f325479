/* SPDX-License-Identifier: BSD-3-Clause */
/* The library's version string, built from the numbers in isoprop/version.h. */
#include "internal.h"
#include "isoprop/version.h"

const char *ip_version(void)
{
    return IP__VERSION_STRING;
}
