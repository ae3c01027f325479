/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: the public API of libisoprop in one include.
 *
 * Brick a volume once (input.h, bricker.h), open the brick file (store.h, layout.h), keep its
 * bricks in a cache with a byte budget (cache.h), count its values to choose an isovalue
 * (histogram.h), extract the isosurface progressively for a
 * camera (camera.h, engine.h, mesh.h) and write it (mesh.h). status.h has the error
 * convention, output.h the rules every output follows, generate.h the test volumes,
 * system.h the clock, memory and thread-count helpers, version.h the version.
 *
 * Drawing (render.h) is not included: it belongs to the separate library libisoprop_render
 * (OpenGL through EGL, the software rasterizer, PNG), so that a program that only bricks and
 * extracts compiles and links against libisoprop alone, even where the render component and
 * its header are not installed. A program that draws includes "isoprop/render.h" too and links
 * both libraries (docs/api.md).
 */
#ifndef ISOPROP_ISOPROP_H
#define ISOPROP_ISOPROP_H

#include "isoprop/status.h"
#include "isoprop/version.h"
#include "isoprop/system.h"
#include "isoprop/volume.h"
#include "isoprop/orientation.h"
#include "isoprop/input.h"
#include "isoprop/output.h"
#include "isoprop/layout.h"
#include "isoprop/bricker.h"
#include "isoprop/store.h"
#include "isoprop/histogram.h"
#include "isoprop/cache.h"
#include "isoprop/camera.h"
#include "isoprop/mesh.h"
#include "isoprop/engine.h"
#include "isoprop/generate.h"

#endif
