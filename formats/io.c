#include "io.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "log.h"

int sb_open_regular(int dir, const char *path, bool follow_symlinks, const char *source)
{
    int fd = openat(dir, path, O_RDONLY | O_CLOEXEC | O_NONBLOCK | (follow_symlinks ? 0 : O_NOFOLLOW));
    if (fd < 0) {
        int err = errno;
        if (source && err == ELOOP)
            sb_error("%s: is a symbolic link; refused", source);
        else if (source)
            sb_error("%s: cannot open: %s", source, strerror(err));
        errno = err;
        return -1;
    }
    struct stat st;
    int flags = fcntl(fd, F_GETFL);
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
        if (source)
            sb_error("%s: not a regular file; refused", source);
        close(fd);
        errno = EINVAL;
        return -1;
    }
    return fd;
}

bool sb_write_all(int fd, const void *data, size_t size)
{
    const char *p = data;
    while (size) {
        ssize_t n = write(fd, p, size);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            if (n == 0)
                errno = EIO;
            return false;
        }
        p += n;
        size -= (size_t)n;
    }
    return true;
}

bool sb_read_all(int fd, void *data, size_t size)
{
    char *p = data;
    while (size) {
        ssize_t n = read(fd, p, size);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            if (n == 0)
                errno = 0;
            return false;
        }
        p += n;
        size -= (size_t)n;
    }
    return true;
}

enum sb_result sb_write_file(const char *path, const void *data, size_t size, const char *what)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        sb_error("%s: cannot create the %s: %s", path, what, strerror(errno));
        return SB_ERR_IO;
    }
    bool ok = sb_write_all(fd, data, size);
    int saved = errno;
    if (close(fd) != 0 && ok) {
        ok = false;
        saved = errno;
    }
    if (!ok) {
        sb_error("%s: cannot write the %s: %s", path, what, strerror(saved));
        unlink(path);
        return SB_ERR_IO;
    }
    return SB_OK;
}

enum sb_result sb_read_file(int dir, const char *path, const char *source, size_t max_bytes, bool follow_symlinks,
                            char **data, size_t *size)
{
    *data = NULL;
    *size = 0;
    int fd = sb_open_regular(dir, path, follow_symlinks, source);
    if (fd < 0)
        return errno == ELOOP ? SB_ERR_UNSAFE_PATH : SB_ERR_IO;
    struct stat st;
    if (fstat(fd, &st) != 0) {
        sb_error("%s: cannot read: %s", source, strerror(errno));
        close(fd);
        return SB_ERR_IO;
    }
    if ((uint64_t)st.st_size > max_bytes) {
        sb_error("%s: larger than %zu bytes; refused", source, max_bytes);
        close(fd);
        return SB_ERR_OUT_OF_RANGE;
    }
    /* Read up to one byte past the cap: the file may have grown since fstat. */
    char *buf = malloc(max_bytes + 1);
    if (!buf) {
        close(fd);
        return SB_ERR_NOMEM;
    }
    size_t n = 0;
    for (;;) {
        ssize_t got = read(fd, buf + n, max_bytes + 1 - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            sb_error("%s: cannot read: %s", source, strerror(errno));
            free(buf);
            close(fd);
            return SB_ERR_IO;
        }
        if (got == 0 || (n += (size_t)got) > max_bytes)
            break;
    }
    close(fd);
    if (n > max_bytes) {
        sb_error("%s: larger than %zu bytes; refused", source, max_bytes);
        free(buf);
        return SB_ERR_OUT_OF_RANGE;
    }
    buf[n] = '\0';
    *data = buf;
    *size = n;
    return SB_OK;
}
