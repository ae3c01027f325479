/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview's text layout, apart from the window so that a unit test can check it: the overlay's
 * text as a table of rows ('\n' between rows) of cells ('\t' between a row's cells), each
 * column starting at one x for every row, in stb_easy_font units (a line is 12 high). */
#ifndef ISOVIEW_LAYOUT_H
#define ISOVIEW_LAYOUT_H

#include <stddef.h>

#define LAYOUT_LINE_HEIGHT 12.0f
#define LAYOUT_MAX_COLUMNS 4
#define LAYOUT_MAX_CELL 255 /* characters: a longer cell is cut */

/* One cell: text[0 .. length) of the laid-out string (no '\n' or '\t'), its top-left corner
 * and width. */
typedef struct text_cell {
    const char *text;
    size_t length;
    float x, y, width;
} text_cell;

/* The keys and what they do, one row each: the key, a tab, the action. */
extern const char isoview_help_table[];

/* The width of text[0 .. length) in stb_easy_font units. */
float layout_text_width(const char *text, size_t length);
/* Replaces each byte of `text` that the font has no glyph for (outside ' ' to '~', which it
 * would look up out of its tables' bounds: UTF-8 in a file name, say) with '?'. */
void layout_printable(char *text);

/* Lays out `text`: column c of every row starts at the same x, the widest cell of column c - 1
 * plus `gap` after column c - 1's x; row r is at y = r * LAYOUT_LINE_HEIGHT. A row with fewer
 * cells leaves the later columns empty; cells after the LAYOUT_MAX_COLUMNS-th join the last.
 * Fills cells[0 .. max_cells) in reading order and returns how many cells the text has (more
 * than max_cells when they did not all fit: the rest are not drawn). *width and *height:
 * the table's extent. */
size_t layout_table(const char *text, float gap, text_cell *cells, size_t max_cells, float *width,
                    float *height);

#endif
