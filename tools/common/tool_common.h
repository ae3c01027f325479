/* SPDX-License-Identifier: BSD-3-Clause */
/* Helpers shared by the programs (not part of the library): option values, errors, JSON. */
#ifndef ISOPROP_TOOL_COMMON_H
#define ISOPROP_TOOL_COMMON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "isoprop/cache.h"
#include "isoprop/camera.h"
#include "isoprop/engine.h"
#include "isoprop/input.h"
#include "isoprop/render.h"
#include "isoprop/status.h"
#include "isoprop/store.h"
#include "isoprop/system.h"
/* the parts: tools/common/NAME.c declares its functions in tool_NAME.h */
#include "tool_values.h"
#include "tool_files.h"
#include "tool_signals.h"
#include "tool_outputs.h"
#include "tool_progress.h"
#include "tool_command_line.h"
#include "tool_options.h"
#include "tool_space.h"
#include "tool_figure.h"
#include "tool_report.h"

#endif
