/* SPDX-License-Identifier: BSD-3-Clause */
/* The text-header helpers shared by the NRRD and MetaImage readers (src/input/text_header.c):
 * the key table dispatch, the shared key parsers and checks, the reading driver, and the one
 * table of sample type names (src/common/volume.c). */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "internal.h"
#include "text_header.h"

typedef struct toy_header {
    ip_text_place at; /* first, as the readers' headers */
    int64_t dims;
    int sizes_count;
    uint64_t sizes[3];
    int spacing_count;
    double spacing[3];
    int has_type;
    ip_type type;
    int custom_calls;
    const char *custom_key;
    int done;
} toy_header;

static ip_status parse_custom(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    toy_header *h = header;
    h->custom_calls++;
    h->custom_key = key->name;
    if (strcmp(value, "bad") == 0)
        return ip__text_bad_value(h, key->name, value, "not good", err);
    return IP_OK;
}

static const ip_text_key toy_key_list[] = {
    {"Dims", BY_DIMS, ip__text_key_dimensions, offsetof(toy_header, dims), 0},
    {"Sizes", BY_DIMS, ip__text_key_u64s, offsetof(toy_header, sizes),
     offsetof(toy_header, sizes_count)},
    {"Spacing", BY_SPACING, ip__text_key_doubles, offsetof(toy_header, spacing),
     offsetof(toy_header, spacing_count)},
    {"Type", BY_TYPE, ip__text_key_type, offsetof(toy_header, type),
     offsetof(toy_header, has_type)},
    {"Custom", BY_NOTHING, parse_custom, 0, 0},
    {"Other name", BY_ENDIAN, parse_custom, 0, 0},
};
static const ip_text_keys nocase_keys = {toy_key_list, 6,     1,
                                         NULL,         "Toy", IP_TYPE_SPELLING_METAIMAGE};
static const ip_text_keys field_keys = {toy_key_list, 6, 0, "field", "TOY", IP_TYPE_SPELLING_NRRD};

static void fresh(toy_header *h, const ip_text_keys *keys)
{
    memset(h, 0, sizeof *h);
    h->at.path = "toy.hdr";
    h->at.line_number = 12;
    h->at.keys = keys;
    h->sizes_count = h->spacing_count = -1;
}

/* Dispatches one key and value (copied: parsers may change the value in place). */
static ip_status dispatch(toy_header *h, const ip_text_keys *keys, const char *key,
                          const char *value, const ip_input_overrides *o, ip_error *err)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", value);
    return ip__text_dispatch(keys, h, key, buf, o, err);
}

/* Dispatching key = value into a fresh header with `keys` fails with IP_ERR_INPUT and
 * `message` in the error. */
static void dispatch_fails(const ip_text_keys *keys, const char *key, const char *value,
                           const char *message)
{
    toy_header h;
    ip_error err;
    fresh(&h, keys);
    CHECK_MSG(dispatch(&h, keys, key, value, NULL, &err) == IP_ERR_INPUT, "%s = %s", key, value);
    CHECK_CONTAINS(err.message, message);
}

static void test_dispatch(void)
{
    toy_header h;
    ip_error err;
    fresh(&h, &nocase_keys);
    CHECK_EQ(dispatch(&h, &nocase_keys, "sizes", "7 5 3", NULL, &err), IP_OK);
    CHECK_EQ(h.sizes_count, 3);
    CHECK_EQ(h.sizes[0], 7);
    CHECK_EQ(h.sizes[2], 3);
    CHECK_EQ(dispatch(&h, &nocase_keys, "SPACING", "0.5 1 2.25", NULL, &err), IP_OK);
    CHECK_EQ(h.spacing_count, 3);
    CHECK_EQ(h.spacing[0], 0.5);
    CHECK_EQ(h.spacing[2], 2.25);
    CHECK_EQ(dispatch(&h, &nocase_keys, "Unknown", "whatever", NULL, &err), IP_OK); /* ignored */
    CHECK_EQ(dispatch(&h, &nocase_keys, "Custom", "fine", NULL, &err), IP_OK);
    CHECK_EQ(h.custom_calls, 1);
    CHECK_STR_EQ(h.custom_key, "Custom");
    dispatch_fails(&nocase_keys, "custom", "bad", "toy.hdr: line 12: bad Custom 'bad': not good");
    /* counts past 3 are reported, only 3 stored */
    CHECK_EQ(dispatch(&h, &nocase_keys, "Sizes", "1 2 3 4", NULL, &err), IP_OK);
    CHECK_EQ(h.sizes_count, 4);
    CHECK_EQ(h.sizes[2], 3);
    dispatch_fails(&nocase_keys, "Sizes", "1 x 3",
                   "toy.hdr: line 12: bad Sizes '1 x 3': not whole numbers");
    dispatch_fails(&nocase_keys, "Spacing", "1 nope", "bad Spacing '1 nope': not numbers");
    /* an empty value: the key as the table spells it, or as "field 'key'" */
    dispatch_fails(&nocase_keys, "CUSTOM", "", "toy.hdr: line 12: Custom has no value");
    fresh(&h, &field_keys);
    dispatch_fails(&field_keys, "Other name", "",
                   "toy.hdr: line 12: field 'Other name' has no value");
    /* case matters where the table says so */
    CHECK_EQ(dispatch(&h, &field_keys, "custom", "bad", NULL, &err), IP_OK);
    CHECK_EQ(h.custom_calls, 0);

    /* a key that an override replaces is not read at all, even when its value is bad */
    ip_input_overrides o;
    memset(&o, 0, sizeof o);
    o.has_dims = 1;
    o.has_endian = 1;
    CHECK_EQ(dispatch(&h, &field_keys, "Sizes", "not numbers", &o, &err), IP_OK);
    CHECK_EQ(h.sizes_count, -1);
    CHECK_EQ(dispatch(&h, &field_keys, "Other name", "bad", &o, &err), IP_OK);
    CHECK_EQ(h.custom_calls, 0);
    CHECK_EQ(dispatch(&h, &field_keys, "Custom", "bad", &o, &err), IP_ERR_INPUT);
}

static void test_shared_parsers(void)
{
    toy_header h;
    ip_error err;
    fresh(&h, &nocase_keys);
    CHECK_EQ(dispatch(&h, &nocase_keys, "Type", "MET_USHORT", NULL, &err), IP_OK);
    CHECK_EQ(h.has_type, 1);
    CHECK_EQ(h.type, IP_UINT16);
    fresh(&h, &nocase_keys);
    CHECK_EQ(dispatch(&h, &nocase_keys, "Type", "ushort", NULL, &err), IP_ERR_INPUT); /* NRRD's */
    CHECK_EQ(h.has_type, 0);
    CHECK_CONTAINS(err.message, "toy.hdr: unsupported Toy Type 'ushort' (supported: MET_UCHAR, "
                                "MET_USHORT, MET_SHORT, MET_FLOAT)");
    fresh(&h, &field_keys);
    CHECK_EQ(dispatch(&h, &field_keys, "Type", "unsigned short int", NULL, &err), IP_OK);
    CHECK_EQ(h.type, IP_UINT16);
    dispatch_fails(&field_keys, "Type", "float32",
                   "unsupported TOY Type 'float32' (supported: uint8, uint16, int16, float)");

    CHECK_EQ(dispatch(&h, &field_keys, "Dims", "3", NULL, &err), IP_OK);
    CHECK_EQ(h.dims, 3);
    dispatch_fails(&field_keys, "Dims", "0", "bad Dims '0': not a positive whole number");
    dispatch_fails(&field_keys, "Dims", "2", "toy.hdr: TOY Dims 2 is not supported (need 3)");
    dispatch_fails(&nocase_keys, "Dims", "4", "toy.hdr: Dims 4 is not supported (need 3)");
}

static void test_checks(void)
{
    toy_header h;
    ip_error err;
    ip_input_overrides o;
    memset(&o, 0, sizeof o);
    fresh(&h, &nocase_keys);
    CHECK_EQ(ip__text_check_dims(&h, 0, "Dims", -1, "Sizes", NULL, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "toy.hdr: missing key 'Dims'");
    CHECK_EQ(ip__text_check_dims(&h, 3, "Dims", -1, "Sizes", NULL, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "toy.hdr: missing key 'Sizes'");
    CHECK_EQ(ip__text_check_dims(&h, 3, "Dims", 2, "Sizes", NULL, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "toy.hdr: Sizes has 2 values, Dims is 3");
    CHECK_EQ(ip__text_check_dims(&h, 3, "Dims", 3, "Sizes", NULL, &err), IP_OK);
    o.has_dims = 1;
    CHECK_EQ(ip__text_check_dims(&h, 0, "Dims", -1, "Sizes", &o, &err), IP_OK);
    fresh(&h, &field_keys);
    CHECK_EQ(ip__text_missing(&h, "encoding", &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "toy.hdr: missing field 'encoding'");

    ip_input_desc desc;
    ip_text_found found;
    memset(&desc, 0, sizeof desc);
    memset(&found, 0, sizeof found);
    const uint64_t sizes[3] = {4, 5, 6};
    ip__text_found_layout(0, IP_INT16, 2, sizes, &desc, &found);
    CHECK(!found.has_type);
    CHECK(!found.has_dims);
    CHECK_EQ(desc.type, IP_UINT8);
    ip__text_found_layout(1, IP_INT16, 3, sizes, &desc, &found);
    CHECK(found.has_type);
    CHECK_EQ(desc.type, IP_INT16);
    CHECK(found.has_dims);
    CHECK_EQ(found.dims[0], 4);
    CHECK_EQ(found.dims[2], 6);
}

/* A whole header through ip__text_read_header: "key value" lines up to "end". */
static ip_status toy_read(ip_text_file *file, void *header, const ip_input_overrides *overrides,
                          ip_error *err)
{
    toy_header *h = header;
    int got;
    ip_status st;
    while ((st = ip__text_next_line(file, &got, err)) == IP_OK && got) {
        char *line = ip__text_trim(file->line);
        char *space = strchr(line, ' ');
        h->at.line_number = file->line_number;
        if (strcmp(line, "end") == 0) {
            h->done = 1;
            break;
        }
        if (!space)
            continue;
        *space = '\0';
        if ((st = ip__text_dispatch(h->at.keys, h, line, ip__text_trim(space + 1), overrides,
                                    err)) != IP_OK)
            return st;
    }
    return st;
}

static void toy_init(void *header)
{
    toy_header *h = header;
    h->sizes_count = h->spacing_count = -1;
}

static ip_status toy_finish(void *header, uint64_t header_end, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    toy_header *h = header;
    ip_status st = ip__text_check_dims(h, h->dims, "Dims", h->sizes_count, "Sizes", overrides, err);
    if (st != IP_OK)
        return st;
    ip__text_found_layout(h->has_type, h->type, h->sizes_count, h->sizes, desc, found);
    desc->data_offset = header_end;
    return IP_OK;
}

static const ip_text_format toy_format = {&nocase_keys, sizeof(toy_header), toy_init, toy_read,
                                          toy_finish};

static void test_read_header(void)
{
    const char *dir = test_tmp_dir("text_header");
    char path[4200];
    snprintf(path, sizeof path, "%s/toy.hdr", dir);
    const char *text = "dims 3\r\nsizes 8 9 10\ntype MET_SHORT\nend\nDATA";
    FILE *f = fopen(path, "wb");
    REQUIRE(f && fputs(text, f) >= 0 && fclose(f) == 0);
    ip_input_desc desc;
    ip_text_found found;
    ip_error err;
    memset(&desc, 0, sizeof desc);
    memset(&found, 0, sizeof found);
    CHECK_EQ(ip__text_read_header(&toy_format, path, NULL, &desc, &found, &err), IP_OK);
    CHECK(found.has_dims);
    CHECK_EQ(found.dims[0], 8);
    CHECK_EQ(found.dims[1], 9);
    CHECK_EQ(found.dims[2], 10);
    CHECK(found.has_type);
    CHECK_EQ(desc.type, IP_INT16);
    CHECK_EQ(desc.data_offset, strlen(text) - strlen("DATA")); /* the bytes the header took */

    f = fopen(path, "wb");
    REQUIRE(f && fputs("dims 3\nsizes 8 9\nend\n", f) >= 0 && fclose(f) == 0);
    CHECK_EQ(ip__text_read_header(&toy_format, path, NULL, &desc, &found, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "toy.hdr: Sizes has 2 values, Dims is 3");
    f = fopen(path, "wb");
    REQUIRE(f && fputs("dims 3\nsizes 8 9 1\ntype double\nend\n", f) >= 0 && fclose(f) == 0);
    CHECK_EQ(ip__text_read_header(&toy_format, path, NULL, &desc, &found, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "unsupported Toy Type 'double'");

    snprintf(path, sizeof path, "%s/absent.hdr", dir);
    CHECK_EQ(ip__text_read_header(&toy_format, path, NULL, &desc, &found, &err), IP_ERR_IO);
    CHECK_CONTAINS(err.message, "absent.hdr: cannot open");
}

static void test_type_names(void)
{
    ip_type t = IP_UINT8;
    CHECK_STR_EQ(ip_type_name(IP_UINT8), "uint8");
    CHECK_STR_EQ(ip_type_name(IP_FLOAT32), "float32");
    CHECK_STR_EQ(ip_type_name((ip_type)9), "unknown");
    /* each spelling set accepts its own names only; ip_type_parse accepts them all */
    CHECK_EQ(ip__type_from_name("float", IP_TYPE_SPELLING_NRRD, &t), IP_OK);
    CHECK_EQ(t, IP_FLOAT32);
    CHECK_EQ(ip__type_from_name("float32", IP_TYPE_SPELLING_NRRD, &t), IP_ERR_ARGUMENT);
    CHECK_EQ(ip__type_from_name("met_short", IP_TYPE_SPELLING_METAIMAGE, &t), IP_OK);
    CHECK_EQ(t, IP_INT16);
    CHECK_EQ(ip__type_from_name("short", IP_TYPE_SPELLING_METAIMAGE, &t), IP_ERR_ARGUMENT);
    CHECK_EQ(ip__type_from_name("u16", IP_TYPE_SPELLING_OTHER, &t), IP_OK);
    CHECK_EQ(t, IP_UINT16);
    CHECK_EQ(ip__type_from_name(NULL, IP_TYPE_SPELLING_ALL, &t), IP_ERR_ARGUMENT);
    t = IP_UINT8;
    CHECK_EQ(ip__type_from_name("uint64", IP_TYPE_SPELLING_ALL, &t), IP_ERR_ARGUMENT);
    CHECK_EQ(t, IP_UINT8);
    const char *every[] = {"uint8",     "uchar", "unsigned char",    "uint8_t",
                           "MET_UCHAR", "u8",    "signed short int", "i16",
                           "MET_FLOAT", "f32",   "float32"};
    int all = 1;
    for (size_t i = 0; i < sizeof every / sizeof every[0]; i++)
        all &= ip_type_parse(every[i], &t) == IP_OK;
    CHECK(all);
    char names[64];
    ip__type_names(IP_TYPE_SPELLING_NRRD, names, sizeof names);
    CHECK_STR_EQ(names, "uint8, uint16, int16, float");
    ip__type_names(IP_TYPE_SPELLING_METAIMAGE, names, sizeof names);
    CHECK_STR_EQ(names, "MET_UCHAR, MET_USHORT, MET_SHORT, MET_FLOAT");
    ip__type_names(IP_TYPE_SPELLING_CANONICAL, names, sizeof names);
    CHECK_STR_EQ(names, "uint8, uint16, int16, float32");
    ip__type_names(IP_TYPE_SPELLING_NRRD, names, 10); /* cut short, terminated */
    CHECK_LT(strlen(names), 10);
}

static const test_case cases[] = {
    TEST_CASE(test_dispatch),    TEST_CASE(test_shared_parsers), TEST_CASE(test_checks),
    TEST_CASE(test_read_header), TEST_CASE(test_type_names),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_text_header");
}
