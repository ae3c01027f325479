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
        return ip_fail(err, IP_ERR_ARGUMENT, "%s: path too long", file->path);
    file->fd = mkstemp(file->temp_path);
    if (file->fd < 0)
        return ip_fail_errno(err, IP_ERR_IO, errno, "%s: cannot create a temporary file in %s",
                             file->path, folder);
    mode_t mask = umask(0);
    umask(mask);
    (void)fchmod(file->fd, 0666 & ~mask);
    file->named = 1;
    return IP_OK;
}

ip_status ip_atomic_create(ip_atomic_file *file, const char *path, int force, ip_error *err)
{
    char folder[IP_PATH_MAX];
    struct stat st;
    memset(file, 0, sizeof *file);
    file->fd = -1;
    file->force = force;
    if (strlen(path) + 32 >= sizeof file->path)
        return ip_fail(err, IP_ERR_ARGUMENT, "%s: path too long", path);
    snprintf(file->path, sizeof file->path, "%s", path);
    if (stat(path, &st) == 0) {
        if (!force)
            return ip_fail(err, IP_ERR_EXISTS, "%s: exists (use --force to overwrite)", path);
        if (S_ISDIR(st.st_mode))
            return ip_fail(err, IP_ERR_ARGUMENT, "%s: is a directory", path);
    }
    folder_of(path, folder, sizeof folder);
    file->fd = open(folder, O_TMPFILE | O_RDWR | O_CLOEXEC, 0666);
    if (file->fd >= 0)
        return IP_OK;
    if (errno == ENOENT || errno == EACCES || errno == ENOTDIR || errno == EROFS)
        return ip_fail_errno(err, IP_ERR_IO, errno, "%s: cannot write in folder %s", path,
                             folder);
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
            return ip_fail(err, IP_ERR_EXISTS, "%s: exists (use --force to overwrite)",
                           file->path);
        return ip_fail_errno(err, IP_ERR_IO, errno, "%s: cannot create", file->path);
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
            return ip_fail_errno(err, IP_ERR_IO, e, "%s: cannot replace", file->path);
        }
        if (errno != EEXIST)
            return ip_fail_errno(err, IP_ERR_IO, errno, "%s: cannot create", file->path);
    }
    return ip_fail(err, IP_ERR_IO, "%s: cannot find a free temporary name", file->path);
}

static ip_status rename_named(ip_atomic_file *file, ip_error *err)
{
    if (!file->force) {
        /* link() refuses to clobber, unlike rename(): the no-overwrite promise holds even if
         * someone created the file since ip_atomic_create(). */
        if (link(file->temp_path, file->path) != 0) {
            int e = errno;
            if (e == EEXIST)
                return ip_fail(err, IP_ERR_EXISTS, "%s: exists (use --force to overwrite)",
                               file->path);
            return ip_fail_errno(err, IP_ERR_IO, e, "%s: cannot create", file->path);
        }
        unlink(file->temp_path);
        return IP_OK;
    }
    if (rename(file->temp_path, file->path) != 0)
        return ip_fail_errno(err, IP_ERR_IO, errno, "%s: cannot replace", file->path);
    return IP_OK;
}

ip_status ip_atomic_commit(ip_atomic_file *file, ip_error *err)
{
    ip_status st;
    if (fsync(file->fd) != 0) {
        st = ip_fail_errno(err, IP_ERR_IO, errno, "%s: fsync failed", file->path);
        ip_atomic_abort(file);
        return st;
    }
    st = file->named ? rename_named(file, err) : link_unnamed(file, err);
    if (st != IP_OK) {
        ip_atomic_abort(file);
        return st;
    }
    close(file->fd);
    file->fd = -1;
    file->named = 0;
    sync_folder(file->path);
    return IP_OK;
}

void ip_atomic_abort(ip_atomic_file *file)
{
    if (file->fd >= 0)
        close(file->fd);
    file->fd = -1;
    if (file->named)
        unlink(file->temp_path);
    file->named = 0;
}

ip_status ip_pwrite_all(int fd, const void *data, size_t size, uint64_t offset,
                        const char *path, ip_error *err)
{
    const unsigned char *p = data;
    while (size > 0) {
        ssize_t n = pwrite(fd, p, size, (off_t)offset);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return ip_fail_errno(err, IP_ERR_IO, errno, "%s: write failed", path);
        }
        if (n == 0)
            return ip_fail(err, IP_ERR_IO, "%s: write failed: no progress", path);
        p += n;
        size -= (size_t)n;
        offset += (uint64_t)n;
    }
    return IP_OK;
}

ip_status ip_pread_all(int fd, void *data, size_t size, uint64_t offset, const char *path,
                       ip_error *err)
{
    unsigned char *p = data;
    while (size > 0) {
        ssize_t n = pread(fd, p, size, (off_t)offset);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return ip_fail_errno(err, IP_ERR_IO, errno, "%s: read failed", path);
        }
        if (n == 0)
            return ip_fail(err, IP_ERR_IO, "%s: unexpected end of file at byte %llu", path,
                           (unsigned long long)offset);
        p += n;
        size -= (size_t)n;
        offset += (uint64_t)n;
    }
    return IP_OK;
}
