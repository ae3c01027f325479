/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview's text layout (tools/isoview/layout.c): the help's second column starts at one x
 * for every row, past the widest key; rows stack by the font's line height; a text without
 * tabs is one cell a row at x = 0; a table too large for the cells given says so. */
#include <string.h>

#include "check.h"
#include "layout.h"

/* The index of the first cell of each row, or -1; returns the number of rows. */
static size_t rows_of(const text_cell *cells, size_t n, size_t first[], size_t max_rows)
{
    size_t rows = 0;
    for (size_t i = 0; i < n && rows < max_rows; i++)
        if (i == 0 || cells[i].y != cells[i - 1].y)
            first[rows++] = i;
    return rows;
}

static void test_help_columns(void)
{
    text_cell cells[64];
    float width, height;
    size_t n = layout_table(isoview_help_table, 8, cells, 64, &width, &height);
    REQUIRE(n <= 64);
    size_t first[32] = {0}, rows = rows_of(cells, n, first, 32);
    CHECK_MSG(rows >= 10 && n == 2 * rows, "%zu rows, %zu cells", rows, n);
    float widest_key = 0;
    for (size_t r = 0; r < rows; r++)
        if (cells[first[r]].width > widest_key)
            widest_key = cells[first[r]].width;
    float action_x = cells[first[0] + 1].x;
    CHECK_EQ(action_x, widest_key + 8);
    for (size_t r = 0; r < rows; r++) {
        const text_cell *key = &cells[first[r]], *action = key + 1;
        CHECK_MSG(key->x == 0 && action->x == action_x, "row %zu: key at %g, action at %g", r,
                  (double)key->x, (double)action->x);
        CHECK_EQ(action->y, key->y);
        CHECK_EQ(key->y, (float)r * LAYOUT_LINE_HEIGHT);
        CHECK_EQ(memchr(key->text, '\t', key->length), NULL);
        CHECK_GT(key->length, 0);
        CHECK_EQ(memchr(action->text, '\n', action->length), NULL);
        CHECK_LE(action->x + action->width, width);
    }
    CHECK_EQ(height, (float)rows * LAYOUT_LINE_HEIGHT);
    /* the key o and its modes are in the help */
    CHECK_NE(strstr(isoview_help_table, "o\toverlay: compact, detailed, off"), NULL);
    /* and the key c, which turns the --clip planes off and on */
    CHECK_NE(strstr(isoview_help_table, "c\tclipping planes (--clip) on / off"), NULL);
}

static void test_plain_lines(void)
{
    text_cell cells[4];
    float width, height;
    const char *text = "iso 1000.5\nrays 12.5 %   87 triangles";
    size_t n = layout_table(text, 8, cells, 4, &width, &height);
    CHECK_EQ(n, 2);
    CHECK_EQ(cells[0].x, 0);
    CHECK_EQ(cells[1].x, 0);
    CHECK_EQ(cells[1].y, LAYOUT_LINE_HEIGHT);
    CHECK_EQ(cells[0].length, 10);
    CHECK(!strncmp(cells[0].text, "iso 1000.5", 10));
    CHECK_EQ(width, cells[1].width);
    CHECK_GT(width, cells[0].width);
    CHECK_EQ(width, layout_text_width("rays 12.5 %   87 triangles", 26));
    CHECK_EQ(height, 2 * LAYOUT_LINE_HEIGHT);
}

static void test_ragged_rows(void)
{
    text_cell cells[8];
    float width, height;
    /* a row with one cell, one with three: each column still starts at one x */
    size_t n = layout_table("a\tbb\tc\nwide key\nk\tv", 4, cells, 8, &width, &height);
    CHECK_EQ(n, 6);
    float key_w = layout_text_width("wide key", 8), mid_w = layout_text_width("bb", 2);
    CHECK_EQ(cells[1].x, key_w + 4);
    CHECK_EQ(cells[5].x, key_w + 4);
    CHECK_EQ(cells[2].x, key_w + 4 + mid_w + 4);
    CHECK_EQ(cells[3].x, 0);
    CHECK_EQ(cells[3].length, 8);
    /* too small a buffer: the count says how many there were */
    CHECK_EQ(layout_table("a\tb\nc\td", 4, cells, 3, &width, &height), 4);
    CHECK_EQ(layout_table("", 4, cells, 8, &width, &height), 0);
    CHECK_EQ(width, 0);
    CHECK_EQ(height, 0);
}

/* Bytes without a glyph (a file name's UTF-8, a control character) count and draw as '?',
 * instead of being looked up out of the font's tables. */
static void test_unprintable(void)
{
    CHECK_EQ(layout_text_width("\xc3\xa9t\xc3\xa9.png", 9), layout_text_width("??t??.png", 9));
    CHECK_EQ(layout_text_width("a\x01\x7f", 3), layout_text_width("a??", 3));
    char text[] = "saved \xc3\xa9\x7f~ ok";
    layout_printable(text);
    CHECK_STR_EQ(text, "saved ???~ ok");
}

static const test_case cases[] = {
    TEST_CASE(test_help_columns),
    TEST_CASE(test_plain_lines),
    TEST_CASE(test_ragged_rows),
    TEST_CASE(test_unprintable),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_isoview_layout");
}
