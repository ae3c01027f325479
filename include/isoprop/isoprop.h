/* isoprop: the whole public API in one include.
 *
 * Brick a volume once (input.h, bricker.h), open the brick file (store.h, layout.h), keep its
 * bricks in a cache with a byte budget (cache.h), extract the isosurface progressively for a
 * camera (camera.h, engine.h, mesh.h) and draw it (render.h). status.h has the error
 * convention, output.h the rules every output follows, generate.h the test volumes,
 * system.h the clock, memory and thread-count helpers, version.h the version.
 */
#ifndef ISOPROP_ISOPROP_H
#define ISOPROP_ISOPROP_H

#include "isoprop/status.h"
#include "isoprop/version.h"
#include "isoprop/system.h"
#include "isoprop/volume.h"
#include "isoprop/input.h"
#include "isoprop/output.h"
#include "isoprop/layout.h"
#include "isoprop/bricker.h"
#include "isoprop/store.h"
#include "isoprop/cache.h"
#include "isoprop/camera.h"
#include "isoprop/mesh.h"
#include "isoprop/engine.h"
#include "isoprop/render.h"
#include "isoprop/generate.h"

#endif
