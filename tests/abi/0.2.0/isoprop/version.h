/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: the library's version, the one source of truth (CMakeLists.txt reads it from here
 * for project(VERSION); the programs print it for --version). Semantic versioning: the major
 * number changes with incompatible API or brick-format changes, the minor with additions, the
 * patch with fixes.
 */
#ifndef ISOPROP_VERSION_H
#define ISOPROP_VERSION_H

#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IP_VERSION_MAJOR 0
#define IP_VERSION_MINOR 2
#define IP_VERSION_PATCH 0

/*! ip_version() : the version of the library linked in, as "MAJOR.MINOR.PATCH" (e.g. "0.2.0");
 *  a constant string, never NULL; thread-safe. */
IP_API const char *ip_version(void);

#ifdef __cplusplus
}
#endif
#endif
