/* SPDX-License-Identifier: BSD-3-Clause */
/* The command line, parsed from the programs' tables of options with getopt_long. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool_common.h"

/* ---- the command-line engine: getopt_long over the tables ----
 *
 * Every row becomes a struct option (its long name without the dashes) and, when its name or
 * alias is a single letter ("-o", "-q"), a letter of the short-option string, so that
 * "--iso=V", "--iso V", "-oFILE", "-o FILE", clustered letters ("-qf"), "--" and unambiguous
 * prefixes of long names ("--mes" for --mesh) all work as getopt_long makes them. A row's
 * getopt_long value is ROW_VALUE + its index in the flattened list of rows. */

#define ROW_VALUE 0x1000
#define HELP_VALUE 0x0fff
#define VERSION_VALUE 0x0ffe

typedef struct option_row {
    const tool_option *option;
    void *base;
} option_row;

typedef struct getopt_tables {
    option_row *rows;
    struct option *longs;
    char shorts[128];
    size_t count;
} getopt_tables;

static int is_short_name(const char *name)
{
    return name && name[0] == '-' && name[1] && name[1] != '-' && !name[2];
}

static void add_short(getopt_tables *g, const char *name, int has_value)
{
    size_t n = strlen(g->shorts);
    if (n + 3 >= sizeof g->shorts)
        return;
    g->shorts[n++] = name[1];
    if (has_value)
        g->shorts[n++] = ':';
    g->shorts[n] = '\0';
}

/* Builds the getopt_long tables; returns 0, or -1 when out of memory. */
static int build_getopt_tables(const tool_command_line *c, getopt_tables *g)
{
    size_t count = 0;
    for (size_t t = 0; t < c->table_count; t++)
        count += c->tables[t].count;
    g->rows = calloc(count ? count : 1, sizeof *g->rows);
    g->longs = calloc(count + 3, sizeof *g->longs);
    if (!g->rows || !g->longs)
        return -1;
    strcpy(g->shorts, ":h"); /* ':': a missing value is reported as such, not as unknown */
    size_t l = 0;
    for (size_t t = 0; t < c->table_count; t++)
        for (size_t k = 0; k < c->tables[t].count; k++) {
            const tool_option *opt = &c->tables[t].options[k];
            int has_value = opt->values >= 1; /* an optional value is taken by hand */
            g->rows[g->count] = (option_row){opt, c->tables[t].base};
            const char *names[2] = {opt->name, opt->alias};
            for (int n = 0; n < 2; n++) {
                if (is_short_name(names[n]))
                    add_short(g, names[n], has_value);
                else if (names[n] && names[n][0] == '-' && names[n][1] == '-')
                    g->longs[l++] =
                        (struct option){names[n] + 2, has_value ? required_argument : no_argument,
                                        NULL, ROW_VALUE + (int)g->count};
            }
            g->count++;
        }
    g->longs[l++] = (struct option){"help", no_argument, NULL, HELP_VALUE};
    g->longs[l++] = (struct option){"version", no_argument, NULL, VERSION_VALUE};
    return 0;
}

/* The row whose short name or alias is `letter`, or -1. */
static int short_row(const getopt_tables *g, int letter)
{
    for (size_t r = 0; r < g->count; r++) {
        const tool_option *opt = g->rows[r].option;
        if ((is_short_name(opt->name) && opt->name[1] == letter) ||
            (is_short_name(opt->alias) && opt->alias[1] == letter))
            return (int)r;
    }
    return -1;
}

/* Takes a row's values (getopt_long's optarg, then what follows in argv for a second or an
 * optional value) and applies them. Returns 0, or 2 after a usage error. */
static int take_row(const tool_command_line *c, const option_row *row, int argc, char **argv)
{
    const tool_option *opt = row->option;
    const char *values[2] = {NULL, NULL};
    if (opt->values >= 1)
        values[0] = optarg;
    if (opt->values == 2) {
        if (optind >= argc)
            return tool_usage_error(c->program, "%s needs %d values", opt->name, opt->values);
        values[1] = argv[optind++];
    }
    if (opt->values == TOOL_OPTIONAL_VALUE && optind < argc && opt->accepts(argv[optind]))
        values[0] = argv[optind++];
    char *field = (char *)row->base + opt->offset;
    if (opt->parse)
        return opt->parse(c->program, opt, values, row->base);
    if (opt->values == 0)
        *(int *)(void *)field = 1;
    else
        *(const char **)(void *)field = values[0];
    return 0;
}

/* The usage error for getopt_long's '?' or ':' on argv[optind - 1]. */
static int getopt_error(const tool_command_line *c, int result, char **argv)
{
    const char *arg = argv[optind - 1];
    if (result == ':')
        return tool_usage_error(c->program, "option '%s' needs a value", arg);
    if (optopt && arg[0] == '-' && arg[1] != '-')
        return tool_usage_error(c->program, "unknown option '-%c' (in '%s')", optopt, arg);
    return tool_usage_error(c->program, "unknown or ambiguous option '%s'", arg);
}

static int parse_getopt(const tool_command_line *c, const getopt_tables *g, int argc, char **argv)
{
    opterr = 0;
    optind = 0; /* start afresh, even when called twice */
    for (;;) {
        int result = getopt_long(argc, argv, g->shorts, g->longs, NULL);
        if (result == -1)
            break;
        if (result == HELP_VALUE || result == 'h') {
            fputs(c->usage, stdout);
            exit(0);
        }
        if (result == VERSION_VALUE) {
            tool_print_version(c->program);
            exit(0);
        }
        if (result == '?' || result == ':')
            return getopt_error(c, result, argv);
        int r = result >= ROW_VALUE ? result - ROW_VALUE : short_row(g, result);
        if (r < 0)
            return tool_usage_error(c->program, "unknown option '%s'", argv[optind - 1]);
        if (take_row(c, &g->rows[r], argc, argv) != 0)
            return 2;
    }
    for (int i = optind; i < argc; i++) {
        if (c->positional && !*c->positional)
            *c->positional = argv[i];
        else
            return tool_usage_error(c->program, "more than one %s ('%s')", c->positional_name,
                                    argv[i]);
    }
    return 0;
}

int tool_parse_command_line(const tool_command_line *c, int argc, char **argv)
{
    getopt_tables g;
    memset(&g, 0, sizeof g);
    int rc = build_getopt_tables(c, &g) == 0 ? parse_getopt(c, &g, argc, argv) : -1;
    free(g.rows);
    free(g.longs);
    if (rc < 0) {
        fprintf(stderr, "%s: out of memory\n", c->program);
        return 2;
    }
    return rc;
}
