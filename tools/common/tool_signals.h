/* SPDX-License-Identifier: BSD-3-Clause */
/* Ctrl-C and SIGTERM: recorded, the engine cancelled, and raised again at the end. */
#ifndef ISOPROP_TOOL_SIGNALS_H
#define ISOPROP_TOOL_SIGNALS_H

#include "isoprop/engine.h"

/* Ctrl-C and SIGTERM. tool_signals_catch() installs handlers that only record the signal
 * (and cancel the engine named by tool_signals_cancel_engine(), an atomic store), so that the
 * program can stop cleanly, write no output and then end as killed by that signal, with
 * tool_signals_reraise() (shell status 130 for SIGINT, 143 for SIGTERM). */
void tool_signals_catch(void);
/* The signal caught so far (SIGINT or SIGTERM), or 0. */
int tool_signal_caught(void);
/* The engine a signal cancels from now on (NULL: none). Before an engine is destroyed, call
 * with NULL: it returns once no handler can still be using the old one. */
void tool_signals_cancel_engine(ip_engine *engine);
/* Forgets the signal caught: the run ends as if none had come (a signal after every output
 * was written, tool_outputs_end()). */
void tool_signals_forget(void);
/* When a signal was caught: flushes stdout and stderr, restores the default action and
 * raises the signal again (the process ends there). Returns when none was caught. */
void tool_signals_reraise(void);

#endif
