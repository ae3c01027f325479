/* SPDX-License-Identifier: BSD-3-Clause */
/* Atomic output files; see atomic_file.h for the guarantees. */
#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "atomic_file.h"
#include "internal.h"
#include "isoprop/output.h"

static void folder_of(const char *path, char *out, size_t size)
{
    char copy[IP_PATH_MAX];
    snprintf(copy, sizeof copy, "%s", path);
    snprintf(out, size, "%s", dirname(copy));
}

static void base_of(const char *path, char *out, size_t size)
{
    char copy[IP_PATH_MAX];
    snprintf(copy, sizeof copy, "%s", path);
    snprintf(out, size, "%s", basename(copy));
}

static ip_status open_named_temp(ip_atomic_file *file, const char *folder, ip_error *err)
{
    char base[IP_PATH_MAX];
    base_of(file->path, base, sizeof base);
    int n = snprintf(file->temp_path, sizeof file->temp_path, "%s/.%s.tmp.XXXXXX", folder, base);
    if (n < 0 || (size_t)n >= sizeof file->temp_path)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: path too long", file->path);
    file->fd = mkstemp(file->temp_path);
    if (file->fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot create a temporary file in %s",
                              file->path, folder);
    mode_t mask = umask(0);
    umask(mask);
    (void)fchmod(file->fd, 0666 & ~mask);
    file->named = 1;
    return IP_OK;
}

/* What a file that is not regular is, for messages. */
static const char *kind_of(mode_t mode)
{
    if (S_ISDIR(mode))
        return "a directory";
    if (S_ISCHR(mode))
        return "a character device";
    if (S_ISBLK(mode))
        return "a block device";
    if (S_ISFIFO(mode))
        return "a FIFO";
    if (S_ISSOCK(mode))
        return "a socket";
    return "not a regular file";
}

/* The rule shared by ip_output_check() and the commit: only regular files are replaced.
 * stat() follows a symbolic link, so a link to a device is refused like the device. */
static ip_status check_replaceable(const char *path, int force, ip_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        if (errno == ENOENT)
            return IP_OK;
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot examine the output path", path);
    }
    if (!S_ISREG(st.st_mode))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: exists and is %s, not a regular file; refusing to replace it "
                        "(even with --force)",
                        path, kind_of(st.st_mode));
    if (!force)
        return ip__fail(err, IP_ERR_EXISTS, "%s: exists (use --force to overwrite)", path);
    return IP_OK;
}

ip_status ip_output_check(const char *path, int force, ip_error *err)
{
    if (!path || !path[0])
        return ip__fail(err, IP_ERR_ARGUMENT, "the output path is empty");
    return check_replaceable(path, force, err);
}

/* The real path of the folder of `path` plus its base name; the path itself when the folder
 * cannot be resolved. */
static void canonical_path(const char *path, char *out, size_t size)
{
    char folder[IP_PATH_MAX], base[IP_PATH_MAX];
    folder_of(path, folder, sizeof folder);
    base_of(path, base, sizeof base);
    char *real = realpath(folder, NULL);
    if (!real) {
        snprintf(out, size, "%s", path);
        return;
    }
    snprintf(out, size, "%s/%s", strcmp(real, "/") == 0 ? "" : real, base);
    free(real);
}

int ip_path_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (!a || !b)
        return 0;
    int have_a = stat(a, &sa) == 0, have_b = stat(b, &sb) == 0;
    if (have_a && have_b)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    if (have_a || have_b)
        return 0;
    char ca[2 * IP_PATH_MAX], cb[2 * IP_PATH_MAX];
    canonical_path(a, ca, sizeof ca);
    canonical_path(b, cb, sizeof cb);
    return strcmp(ca, cb) == 0;
}

ip_status ip_output_not_input(const char *output_path, const char *input_path, ip_error *err)
{
    if (!ip_path_same_file(output_path, input_path))
        return IP_OK;
    if (strcmp(output_path, input_path) == 0)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: is an input of this run; refusing to write "
                        "over it",
                        output_path);
    return ip__fail(err, IP_ERR_ARGUMENT,
                    "%s: is the same file as the input %s; refusing to "
                    "write over it",
                    output_path, input_path);
}

ip_status ip__atomic_create(ip_atomic_file *file, const char *path, int force, ip_error *err)
{
    char folder[IP_PATH_MAX];
    memset(file, 0, sizeof *file);
    file->fd = -1;
    file->force = force;
    if (strlen(path) + 32 >= sizeof file->path)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: path too long", path);
    snprintf(file->path, sizeof file->path, "%s", path);
    ip_status st = ip_output_check(path, force, err);
    if (st != IP_OK)
        return st;
    folder_of(path, folder, sizeof folder);
    file->fd = open(folder, O_TMPFILE | O_RDWR | O_CLOEXEC, 0666);
    if (file->fd >= 0)
        return IP_OK;
    if (errno == ENOENT || errno == EACCES || errno == ENOTDIR || errno == EROFS)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot write in folder %s", path, folder);
    return open_named_temp(file, folder, err);
}

static void sync_folder(const char *path)
{
    char folder[IP_PATH_MAX];
    folder_of(path, folder, sizeof folder);
    int dfd = open(folder, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        (void)fsync(dfd);
        close(dfd);
    }
}

/* Gives the unnamed file a name: `target` directly, or (force) a unique sibling then rename. */
static ip_status link_unnamed(ip_atomic_file *file, ip_error *err)
{
    char proc[64];
    snprintf(proc, sizeof proc, "/proc/self/fd/%d", file->fd);
    if (!file->force) {
        if (linkat(AT_FDCWD, proc, AT_FDCWD, file->path, AT_SYMLINK_FOLLOW) == 0)
            return IP_OK;
        if (errno == EEXIST)
            return ip__fail(err, IP_ERR_EXISTS, "%s: exists (use --force to overwrite)",
                            file->path);
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot create", file->path);
    }
    char folder[IP_PATH_MAX], base[IP_PATH_MAX], temp[2 * IP_PATH_MAX + 64];
    folder_of(file->path, folder, sizeof folder);
    base_of(file->path, base, sizeof base);
    for (int attempt = 0; attempt < 100; attempt++) {
        snprintf(temp, sizeof temp, "%s/.%s.tmp.%ld.%d", folder, base, (long)getpid(), attempt);
        if (linkat(AT_FDCWD, proc, AT_FDCWD, temp, AT_SYMLINK_FOLLOW) == 0) {
            if (rename(temp, file->path) == 0)
                return IP_OK;
            int e = errno;
            unlink(temp);
            return ip__fail_errno(err, IP_ERR_IO, e, "%s: cannot replace", file->path);
        }
        if (errno != EEXIST)
            return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot create", file->path);
    }
    return ip__fail(err, IP_ERR_IO, "%s: cannot find a free temporary name", file->path);
}

static ip_status rename_named(ip_atomic_file *file, ip_error *err)
{
    if (!file->force) {
        /* link() refuses to clobber, unlike rename(): the no-overwrite promise holds even if
         * someone created the file since ip__atomic_create(). */
        if (link(file->temp_path, file->path) != 0) {
            int e = errno;
            if (e == EEXIST)
                return ip__fail(err, IP_ERR_EXISTS, "%s: exists (use --force to overwrite)",
                                file->path);
            return ip__fail_errno(err, IP_ERR_IO, e, "%s: cannot create", file->path);
        }
        unlink(file->temp_path);
        return IP_OK;
    }
    if (rename(file->temp_path, file->path) != 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot replace", file->path);
    return IP_OK;
}

ip_status ip__atomic_commit(ip_atomic_file *file, ip_error *err)
{
    ip_status st;
    if (fsync(file->fd) != 0) {
        st = ip__fail_errno(err, IP_ERR_IO, errno, "%s: fsync failed", file->path);
        ip__atomic_abort(file);
        return st;
    }
    /* Again, as late as possible: something not regular may have appeared since the create
     * (rename() would replace a device node or a FIFO with this file). */
    st = check_replaceable(file->path, file->force, err);
    if (st == IP_OK)
        st = file->named ? rename_named(file, err) : link_unnamed(file, err);
    if (st != IP_OK) {
        ip__atomic_abort(file);
        return st;
    }
    close(file->fd);
    file->fd = -1;
    file->named = 0;
    sync_folder(file->path);
    return IP_OK;
}

void ip__atomic_abort(ip_atomic_file *file)
{
    if (file->fd >= 0)
        close(file->fd);
    file->fd = -1;
    if (file->named)
        unlink(file->temp_path);
    file->named = 0;
}

ip_status ip__pwrite_all(int fd, const void *data, size_t size, uint64_t offset, const char *path,
                         ip_error *err)
{
    const unsigned char *p = data;
    while (size > 0) {
        ssize_t n = pwrite(fd, p, size, (off_t)offset);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return ip__fail_errno(err, IP_ERR_IO, errno, "%s: write failed", path);
        }
        if (n == 0)
            return ip__fail(err, IP_ERR_IO, "%s: write failed: no progress", path);
        p += n;
        size -= (size_t)n;
        offset += (uint64_t)n;
    }
    return IP_OK;
}

ip_status ip__write_at(int fd, int stream, const void *data, size_t size, uint64_t offset,
                       const char *path, ip_error *err)
{
    if (!stream)
        return ip__pwrite_all(fd, data, size, offset, path, err);
    const unsigned char *p = data;
    while (size > 0) {
        ssize_t n = write(fd, p, size);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            return ip__fail_errno(err, IP_ERR_IO, errno, "%s: write failed", path);
        if (n == 0)
            return ip__fail(err, IP_ERR_IO, "%s: write failed: no progress", path);
        p += n;
        size -= (size_t)n;
    }
    return IP_OK;
}

ip_status ip__pread_all(int fd, void *data, size_t size, uint64_t offset, const char *path,
                        ip_error *err)
{
    unsigned char *p = data;
    while (size > 0) {
        ssize_t n = pread(fd, p, size, (off_t)offset);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return ip__fail_errno(err, IP_ERR_IO, errno, "%s: read failed", path);
        }
        if (n == 0)
            return ip__fail(err, IP_ERR_IO, "%s: unexpected end of file at byte %llu", path,
                            (unsigned long long)offset);
        p += n;
        size -= (size_t)n;
        offset += (uint64_t)n;
    }
    return IP_OK;
}

ip_status ip_output_write(const char *path, const void *data, size_t size, int force, ip_error *err)
{
    ip_atomic_file out;
    if (!path || (!data && size))
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_output_write: path and data are required");
    ip_status st = ip__atomic_create(&out, path, force, err);
    if (st != IP_OK)
        return st;
    st = ip__pwrite_all(out.fd, data, size, 0, path, err);
    if (st == IP_OK)
        return ip__atomic_commit(&out, err);
    ip__atomic_abort(&out);
    return st;
}
