/* SPDX-License-Identifier: BSD-3-Clause */
/* The output rules (isoprop/output.h) and where the library applies them: an existing file is
 * kept without force, only regular files are ever replaced (a FIFO, a device, a directory or a
 * link to a device is refused even with force), an output is never an input however it is
 * spelled, and whole files are written all-or-nothing. Also the version and non-regular
 * inputs (a FIFO is refused at once, never waited on). */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "isoprop/bricker.h"
#include "isoprop/generate.h"
#include "isoprop/input.h"
#include "isoprop/mesh.h"
#include "isoprop/output.h"
#include "isoprop/render.h"
#include "isoprop/version.h"

static char scratch[4096];

static const char *at(char *buf, const char *name)
{
    int n = snprintf(buf, 4096, "%s/%s", scratch, name);
    REQUIRE(n > 0 && n < 4096);
    return buf;
}

/* printf into a 4096-byte path buffer; the path must fit. */
static const char *format_path(char *buf, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, 4096, fmt, ap);
    va_end(ap);
    REQUIRE(n > 0 && n < 4096);
    return buf;
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    REQUIRE(f != NULL);
    REQUIRE(fputs(text, f) >= 0);
    REQUIRE(fclose(f) == 0);
}

/* The whole file as a string (small files only). */
static const char *read_text(const char *path)
{
    static char buf[4096];
    FILE *f = fopen(path, "rb");
    if (!f)
        return "(missing)";
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

/* Files in the scratch folder whose names hold ".tmp": leftovers of a failed write. */
static int temporaries_left(void)
{
    char cmd[4200];
    snprintf(cmd, sizeof cmd, "ls -a '%s' | grep -q '\\.tmp'", scratch);
    return system(cmd) == 0;
}

static void test_version(void)
{
    char want[64];
    snprintf(want, sizeof want, "%d.%d.%d", IP_VERSION_MAJOR, IP_VERSION_MINOR, IP_VERSION_PATCH);
    CHECK_NE(ip_version(), NULL);
    CHECK_MSG(strcmp(ip_version(), want) == 0, "ip_version() %s, header %s", ip_version(), want);
}

static void test_output_check(void)
{
    char a[4096], d[4096], f[4096];
    ip_error err;
    at(a, "absent.txt");
    CHECK_EQ(ip_output_check(a, 0, &err), IP_OK);
    CHECK_EQ(ip_output_check(a, 1, &err), IP_OK);
    write_text(a, "kept");
    CHECK_EQ(ip_output_check(a, 0, &err), IP_ERR_EXISTS);
    CHECK_CONTAINS(err.message, "absent.txt");
    CHECK_CONTAINS(err.message, "--force");
    CHECK_EQ(ip_output_check(a, 1, &err), IP_OK);
    at(d, "folder");
    REQUIRE(mkdir(d, 0777) == 0);
    CHECK_EQ(ip_output_check(d, 1, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "a directory");
    at(f, "fifo");
    REQUIRE(mkfifo(f, 0666) == 0);
    CHECK_EQ(ip_output_check(f, 1, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "a FIFO");
    CHECK_EQ(ip_output_check("/dev/null", 1, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "/dev/null");
    CHECK_CONTAINS(err.message, "character device");
    CHECK_EQ(ip_output_check("", 1, &err), IP_ERR_ARGUMENT);
}

static void test_same_file(void)
{
    char a[4096], b[4096], link_path[4096], hard[4096], spelled[4096], other[4096], cwd[4096];
    at(a, "same.raw");
    write_text(a, "input");
    CHECK(ip_path_same_file(a, a));
    /* the same file spelled another way: through "..", through a symbolic link, a hard link */
    format_path(spelled, "%s/../%s/./same.raw", scratch, strrchr(scratch, '/') + 1);
    CHECK(ip_path_same_file(a, spelled));
    at(link_path, "same-link.raw");
    REQUIRE(symlink(a, link_path) == 0);
    CHECK(ip_path_same_file(a, link_path));
    at(hard, "same-hard.raw");
    REQUIRE(link(a, hard) == 0);
    CHECK(ip_path_same_file(a, hard));
    at(other, "other.raw");
    write_text(other, "input");
    CHECK(!ip_path_same_file(a, other));
    /* outputs that do not exist yet: the same folder and name, however spelled */
    at(b, "new.png");
    format_path(spelled, "%s/./new.png", scratch);
    CHECK(ip_path_same_file(b, spelled));
    REQUIRE(getcwd(cwd, sizeof cwd) != NULL);
    REQUIRE(chdir(scratch) == 0);
    CHECK(ip_path_same_file("new.png", b));
    CHECK(ip_path_same_file("new.png", "./new.png"));
    CHECK(!ip_path_same_file("new.png", "new.ply"));
    CHECK(!ip_path_same_file("new.png", "same.raw"));
    REQUIRE(chdir(cwd) == 0);
    ip_error err;
    CHECK_EQ(ip_output_not_input(other, a, &err), IP_OK);
    CHECK_EQ(ip_output_not_input(link_path, a, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "same-link.raw");
    CHECK_CONTAINS(err.message, "same.raw");
}

static void test_output_write(void)
{
    char p[4096], f[4096], d[4096];
    ip_error err;
    at(p, "whole.json");
    CHECK_EQ(ip_output_write(p, "{}\n", 3, 0, &err), IP_OK);
    CHECK_STR_EQ(read_text(p), "{}\n");
    CHECK_EQ(ip_output_write(p, "{\"x\": 1}\n", 9, 0, &err), IP_ERR_EXISTS);
    CHECK_STR_EQ(read_text(p), "{}\n");
    CHECK_EQ(ip_output_write(p, "{\"x\": 1}\n", 9, 1, &err), IP_OK);
    CHECK_STR_EQ(read_text(p), "{\"x\": 1}\n");
    /* a FIFO, a device, a directory, a link to a device: refused even with force, untouched */
    at(f, "out-fifo");
    REQUIRE(mkfifo(f, 0666) == 0);
    CHECK_EQ(ip_output_write(f, "x", 1, 1, &err), IP_ERR_ARGUMENT);
    struct stat st;
    if (CHECK_EQ(lstat(f, &st), 0))
        CHECK(S_ISFIFO(st.st_mode));
    at(d, "out-dir");
    REQUIRE(mkdir(d, 0777) == 0);
    CHECK_EQ(ip_output_write(d, "x", 1, 1, &err), IP_ERR_ARGUMENT);
    if (CHECK_EQ(stat(d, &st), 0))
        CHECK(S_ISDIR(st.st_mode));
    char l[4096];
    at(l, "null-link");
    REQUIRE(symlink("/dev/null", l) == 0);
    CHECK_EQ(ip_output_write(l, "x", 1, 1, &err), IP_ERR_ARGUMENT);
    if (CHECK_EQ(lstat(l, &st), 0))
        CHECK(S_ISLNK(st.st_mode));
    if (CHECK_EQ(stat("/dev/null", &st), 0))
        CHECK(S_ISCHR(st.st_mode));
    /* the library's other writers follow the same rule */
    uint8_t rgba[4 * 4] = {0};
    CHECK_EQ(ip_png_write(f, rgba, 2, 2, 1, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_png_write("/dev/null", rgba, 2, 2, 1, &err), IP_ERR_ARGUMENT);
    ip_mesh mesh;
    ip_mesh_init(&mesh);
    CHECK_EQ(ip_mesh_write_ply(&mesh, f, 1, &err), IP_ERR_ARGUMENT);
    ip_gen_params params = {sizeof(ip_gen_params), IP_FIELD_SPHERE, {4, 4, 4}, IP_UINT8, 0.0, 1};
    CHECK_EQ(ip_generate_write(&params, f, 1, &err), IP_ERR_ARGUMENT);
    if (CHECK_EQ(lstat(f, &st), 0))
        CHECK(S_ISFIFO(st.st_mode));
    CHECK(!temporaries_left());
}

/* Bricking and upsampling never write over what they read, even with force. */
static void test_output_is_input(void)
{
    char raw[4096], spelled[4096], ibv[4096], header[4096], data[4096];
    ip_error err;
    ip_gen_params params = {sizeof(ip_gen_params), IP_FIELD_SPHERE, {8, 6, 5}, IP_UINT8, 0.0, 1};
    at(raw, "sphere_8x6x5_uint8.raw");
    REQUIRE(ip_generate_write(&params, raw, 0, &err) == IP_OK);
    ip_input_desc desc;
    REQUIRE(ip_input_describe(raw, NULL, &desc, &err) == IP_OK);
    struct stat before, after;
    REQUIRE(stat(raw, &before) == 0);
    ip_bricker_options options;
    ip_bricker_options_default(&options);
    options.force = 1;
    options.threads = 1;
    CHECK_EQ(ip_bricker_run(&desc, raw, &options, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "sphere_8x6x5_uint8.raw");
    format_path(spelled, "%s/./sphere_8x6x5_uint8.raw", scratch);
    CHECK_EQ(ip_bricker_run(&desc, spelled, &options, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_upsample_write(&desc, 2, raw, 1, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_upsample_write(&desc, 1, spelled, 1, &err), IP_ERR_ARGUMENT);
    REQUIRE(stat(raw, &after) == 0);
    CHECK_EQ(after.st_ino, before.st_ino);
    CHECK_EQ(after.st_size, before.st_size);
    /* a detached header: its data file is an input too */
    at(header, "detached.nhdr");
    at(data, "sphere_8x6x5_uint8.raw");
    char text[8192];
    snprintf(text, sizeof text,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 8 6 5\n"
             "encoding: raw\ndata file: %s\n",
             data);
    write_text(header, text);
    REQUIRE(ip_input_describe(header, NULL, &desc, &err) == IP_OK);
    CHECK_EQ(ip_bricker_run(&desc, data, &options, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_bricker_run(&desc, header, &options, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_upsample_write(&desc, 2, data, 1, &err), IP_ERR_ARGUMENT);
    REQUIRE(stat(raw, &after) == 0);
    CHECK_EQ(after.st_ino, before.st_ino);
    CHECK_EQ(after.st_size, before.st_size);
    /* and a brick file that is not an input is written */
    at(ibv, "good.ibv");
    CHECK_EQ(ip_bricker_run(&desc, ibv, &options, NULL, &err), IP_OK);
    /* an existing device or FIFO is never replaced by a brick file */
    CHECK_EQ(ip_bricker_run(&desc, "/dev/null", &options, NULL, &err), IP_ERR_ARGUMENT);
    CHECK(!temporaries_left());
}

static volatile sig_atomic_t alarm_rang;

static void on_alarm(int sig)
{
    (void)sig;
    alarm_rang = 1;
}

/* A FIFO where a volume or a header should be is refused at once: opening one for reading
 * would wait for a writer forever. An alarm turns a hang into a failed check. */
static void test_fifo_inputs(void)
{
    char f[4096], named[4096], header[4096], mhd[4096];
    ip_error err;
    ip_input_desc desc;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm; /* no SA_RESTART: a blocked open() returns EINTR */
    sigaction(SIGALRM, &sa, NULL);
    alarm(10);
    at(named, "fifo_4x4x4_uint8.raw");
    REQUIRE(mkfifo(named, 0666) == 0);
    CHECK_EQ(ip_input_describe(named, NULL, &desc, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "not a regular file");
    at(f, "fifo.nrrd");
    REQUIRE(mkfifo(f, 0666) == 0);
    CHECK_EQ(ip_input_describe(f, NULL, &desc, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "fifo.nrrd: not a regular file");
    at(mhd, "fifo.mhd");
    REQUIRE(mkfifo(mhd, 0666) == 0);
    CHECK_EQ(ip_input_describe(mhd, NULL, &desc, &err), IP_ERR_INPUT);
    at(header, "to-fifo.nhdr");
    write_text(header, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n"
                       "data file: fifo_4x4x4_uint8.raw\n");
    CHECK_EQ(ip_input_describe(header, NULL, &desc, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "not a regular file");
    /* a data file that turns into a FIFO after it was described */
    char raw[4096];
    at(raw, "later_4x4x4_uint8.raw");
    unsigned char zeros[64] = {0};
    FILE *w = fopen(raw, "wb");
    REQUIRE(w && fwrite(zeros, 1, sizeof zeros, w) == sizeof zeros && fclose(w) == 0);
    REQUIRE(ip_input_describe(raw, NULL, &desc, &err) == IP_OK);
    REQUIRE(unlink(raw) == 0 && mkfifo(raw, 0666) == 0);
    ip_input_reader *reader = NULL;
    CHECK_EQ(ip_input_open(&desc, &reader, &err), IP_ERR_INPUT);
    CHECK_EQ(reader, NULL);
    alarm(0);
    CHECK_MSG(!alarm_rang, "an input FIFO hung for 10 s");
}

static const test_case cases[] = {
    TEST_CASE(test_version),      TEST_CASE(test_output_check),    TEST_CASE(test_same_file),
    TEST_CASE(test_output_write), TEST_CASE(test_output_is_input), TEST_CASE(test_fifo_inputs),
};

static void make_scratch_dir(void)
{
    snprintf(scratch, sizeof scratch, "%s", test_tmp_dir("test_output"));
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_output", make_scratch_dir, NULL);
}
