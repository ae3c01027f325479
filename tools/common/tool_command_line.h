/* SPDX-License-Identifier: BSD-3-Clause */
/* The programs' command lines, parsed from tables of options. */
#ifndef ISOPROP_TOOL_COMMAND_LINE_H
#define ISOPROP_TOOL_COMMAND_LINE_H

#include <stddef.h>

/* ---- the command line, parsed from tables ----
 *
 * A program describes its options in tables of tool_option (one of them may be the shared
 * view options, tool_view_option_table()), and tool_parse_command_line() walks argv once,
 * left to right: -h and --help print the program's usage on stdout and exit 0, --version its
 * version (exit 0); an option of a table takes its values; anything else starting with '-'
 * (but "-" alone) is "unknown or incomplete option '...'", as is an option without all its
 * values; the rest is the one positional argument. */

/* tool_option.values for an option whose value is optional: the next argument is its value
 * when `accepts` says so (isobrick --hc [LEVEL]). */
#define TOOL_OPTIONAL_VALUE (-1)

typedef struct tool_option tool_option;

/* Parses an option's values (values[0] .. ; values[0] is NULL for an absent optional value)
 * into the struct at `base` that the table describes (the field at base + option->offset,
 * or several). Returns 0, or 2 after a usage error (tool_usage_error()). */
typedef int tool_option_parse(const char *program, const tool_option *option,
                              const char *const *values, void *base);

struct tool_option {
    const char *name;  /* "--size" */
    const char *alias; /* a second name ("-q"), or NULL */
    int values;        /* the values after the name: 0, 1, 2 or TOOL_OPTIONAL_VALUE */
    /* without parse: a flag (values 0) sets the int at base + offset to 1, a text (values 1)
     * stores the value as the const char * at base + offset */
    size_t offset;
    tool_option_parse *parse;          /* NULL: a flag or a text, as above */
    const char *problem;               /* for parsers that use it: "is not a number" */
    int (*accepts)(const char *value); /* TOOL_OPTIONAL_VALUE: whether it is the value */
};

/* A table and the struct its options fill. */
typedef struct tool_option_table {
    const tool_option *options;
    size_t count;
    void *base;
} tool_option_table;

typedef struct tool_command_line {
    const char *program; /* for messages: "isorender" */
    const char *usage;   /* --help's text */
    const tool_option_table *tables;
    size_t table_count;
    const char **positional;     /* receives the positional argument (NULL when none) */
    const char *positional_name; /* for "more than one NAME ('...')": "file", "input" */
} tool_command_line;

/* Parses argv[1 ..] as described above. Returns 0, or 2 after printing a usage error; exits
 * with status 0 after --help or --version. */
int tool_parse_command_line(const tool_command_line *c, int argc, char **argv);

#endif
