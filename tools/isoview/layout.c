/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview's text layout: the help table and the columns of the overlay's text. */
#include <string.h>

/* The font is a header of static functions (some unused here) in its own style: its warnings
 * are not ours (CMake also adds its folder as a system include folder). */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-braces"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

#include "layout.h"

const char isoview_help_table[] = "left drag\torbit around the target\n"
                                  "right drag\tpan\n"
                                  "wheel\tzoom\n"
                                  "Up / Down\tisovalue +/- 1 % of the value range\n"
                                  "Shift+Up/Down\tisovalue +/- 0.1 %\n"
                                  "PgUp / PgDn\tisovalue +/- 10 %\n"
                                  "i\ttype an isovalue (Enter applies, Esc cancels)\n"
                                  "r\treset the view\n"
                                  "p\tpause / resume refinement\n"
                                  "f\tfull extraction (until the next change)\n"
                                  "c\tclipping planes (--clip) on / off\n"
                                  "s\tsave a screenshot (isoview-NNN.png)\n"
                                  "o\toverlay: compact, detailed, off\n"
                                  "h\tthis help\n"
                                  "Esc\tquit";

void layout_printable(char *text)
{
    for (; *text; text++)
        if (*text < ' ' || *text > '~')
            *text = '?';
}

float layout_text_width(const char *text, size_t length)
{
    char copy[LAYOUT_MAX_CELL + 1];
    if (length > LAYOUT_MAX_CELL)
        length = LAYOUT_MAX_CELL;
    memcpy(copy, text, length);
    copy[length] = 0;
    layout_printable(copy);
    return (float)stb_easy_font_width(copy);
}

/* The end of the cell that starts at `text`: the next '\t' (unless it is the row's last
 * column, which takes the rest of the row), '\n' or the end. */
static const char *cell_end(const char *text, int last_column)
{
    const char *end = text;
    while (*end && *end != '\n' && (last_column || *end != '\t'))
        end++;
    return end;
}

/* Calls visit(cell, user) for each cell of text with its column and row (x and width not yet
 * set); returns the number of cells. */
static size_t each_cell(const char *text, void (*visit)(text_cell *, int, size_t, void *),
                        void *user)
{
    size_t count = 0, row = 0;
    const char *p = text;
    while (*p) {
        for (int column = 0;; column++) {
            const char *end = cell_end(p, column == LAYOUT_MAX_COLUMNS - 1);
            text_cell cell = {p, (size_t)(end - p), 0, (float)row * LAYOUT_LINE_HEIGHT, 0};
            cell.width = layout_text_width(cell.text, cell.length);
            visit(&cell, column, count++, user);
            p = end;
            if (*p != '\t')
                break;
            p++;
        }
        if (*p == '\n')
            p++;
        row++;
    }
    return count;
}

typedef struct layout_pass {
    float widest[LAYOUT_MAX_COLUMNS];
    float x[LAYOUT_MAX_COLUMNS];
    text_cell *cells;
    size_t max_cells;
} layout_pass;

static void measure_cell(text_cell *cell, int column, size_t index, void *user)
{
    layout_pass *pass = user;
    (void)index;
    if (cell->width > pass->widest[column])
        pass->widest[column] = cell->width;
}

static void place_cell(text_cell *cell, int column, size_t index, void *user)
{
    layout_pass *pass = user;
    cell->x = pass->x[column];
    if (index < pass->max_cells)
        pass->cells[index] = *cell;
}

size_t layout_table(const char *text, float gap, text_cell *cells, size_t max_cells, float *width,
                    float *height)
{
    layout_pass pass;
    memset(&pass, 0, sizeof pass);
    pass.cells = cells;
    pass.max_cells = max_cells;
    each_cell(text, measure_cell, &pass);
    *width = 0;
    for (int c = 0; c < LAYOUT_MAX_COLUMNS; c++) {
        pass.x[c] = c ? pass.x[c - 1] + pass.widest[c - 1] + gap : 0;
        if (pass.widest[c] > 0)
            *width = pass.x[c] + pass.widest[c];
    }
    size_t count = each_cell(text, place_cell, &pass);
    size_t rows = 0;
    for (const char *p = text; *p; p++)
        rows += *p == '\n';
    *height = *text ? (float)(rows + 1) * LAYOUT_LINE_HEIGHT : 0;
    return count;
}
