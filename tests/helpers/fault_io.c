/* SPDX-License-Identifier: BSD-3-Clause */
/* A full or failing disk for the end-to-end tests, loaded with LD_PRELOAD: writes to regular
 * files fail once a byte budget is spent, or one call of a kind fails, with the errno asked.
 *
 *   IP_FAULT_BYTES=N     pwrite()/write() to regular files succeed for N bytes in all (the
 *                        call that crosses N writes what fits), then fail
 *   IP_FAULT_CALL=NAME   instead, the IP_FAULT_NTH-th (default 1) call of NAME fails: fsync,
 *                        fdatasync, rename, linkat or close (of a regular file)
 *   IP_FAULT_ERRNO=E     ENOSPC (default), EIO or EDQUOT
 *
 * Only regular files are touched: pipes, sockets, terminals and devices (the programs'
 * standard output, MPI, X) write as usual. Counts are per process. Used by
 * tests/tools/full_disk.sh. */
#include <dlfcn.h>
#include <errno.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

static atomic_long bytes_left = -2; /* -2: not read yet; -1: no byte budget */
static atomic_long calls_seen;

static int fault_errno(void)
{
    const char *e = getenv("IP_FAULT_ERRNO");
    if (e && !strcmp(e, "EIO"))
        return EIO;
    if (e && !strcmp(e, "EDQUOT"))
        return EDQUOT;
    return ENOSPC;
}

static int regular(int fd)
{
    struct stat st;
    return fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
}

/* How many of `size` bytes may be written now (size when there is no budget); 0 and errno set
 * once it is spent. */
static size_t allowed(int fd, size_t size)
{
    long left = atomic_load(&bytes_left);
    if (left == -2) {
        const char *b = getenv("IP_FAULT_BYTES");
        long budget = b ? atol(b) : -1;
        atomic_compare_exchange_strong(&bytes_left, &left, budget);
        left = atomic_load(&bytes_left);
    }
    if (left < 0 || size == 0 || !regular(fd))
        return size;
    for (;;) {
        size_t n = (size_t)left < size ? (size_t)left : size;
        if (atomic_compare_exchange_weak(&bytes_left, &left, left - (long)n)) {
            if (n == 0)
                errno = fault_errno();
            return n;
        }
    }
}

/* 1 when this call of `name` is the one to fail. */
static int fails(const char *name)
{
    const char *call = getenv("IP_FAULT_CALL");
    if (!call || strcmp(call, name) != 0)
        return 0;
    const char *nth = getenv("IP_FAULT_NTH");
    long n = nth ? atol(nth) : 1;
    return atomic_fetch_add(&calls_seen, 1) + 1 == n;
}

#define REAL(name, type) ((type)dlsym(RTLD_NEXT, #name))

ssize_t pwrite(int fd, const void *buf, size_t count, off_t offset)
{
    size_t n = allowed(fd, count);
    if (n == 0 && count > 0)
        return -1;
    return REAL(pwrite, ssize_t(*)(int, const void *, size_t, off_t))(fd, buf, n, offset);
}

ssize_t pwrite64(int fd, const void *buf, size_t count, off_t offset)
{
    return pwrite(fd, buf, count, offset);
}

ssize_t write(int fd, const void *buf, size_t count)
{
    size_t n = allowed(fd, count);
    if (n == 0 && count > 0)
        return -1;
    return REAL(write, ssize_t(*)(int, const void *, size_t))(fd, buf, n);
}

int fsync(int fd)
{
    if (regular(fd) && fails("fsync")) {
        errno = fault_errno();
        return -1;
    }
    return REAL(fsync, int (*)(int))(fd);
}

int fdatasync(int fd)
{
    if (regular(fd) && fails("fdatasync")) {
        errno = fault_errno();
        return -1;
    }
    return REAL(fdatasync, int (*)(int))(fd);
}

int rename(const char *from, const char *to)
{
    if (fails("rename")) {
        errno = fault_errno();
        return -1;
    }
    return REAL(rename, int (*)(const char *, const char *))(from, to);
}

int linkat(int olddirfd, const char *oldpath, int newdirfd, const char *newpath, int flags)
{
    if (fails("linkat")) {
        errno = fault_errno();
        return -1;
    }
    return REAL(linkat, int (*)(int, const char *, int, const char *, int))(
        olddirfd, oldpath, newdirfd, newpath, flags);
}

int close(int fd)
{
    if (regular(fd) && fails("close")) {
        REAL(close, int (*)(int))(fd);
        errno = fault_errno();
        return -1;
    }
    return REAL(close, int (*)(int))(fd);
}
