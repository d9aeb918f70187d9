/*
 * Whole reads and writes on file descriptors, past EINTR and short
 * transfers, and a whole file written from memory: the one place the
 * readers and writers of formats/ (and the mesh importer's pipe) do it.
 */
#ifndef SB_IO_H
#define SB_IO_H

#include <stdbool.h>
#include <stddef.h>

#include "result.h"

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Open `path` (relative to the directory fd `dir`, or AT_FDCWD) for
 * reading, only if it is a regular file: opened without blocking, so that a
 * FIFO with no writer or a device cannot stall the caller, checked, then
 * made blocking again. Returns the descriptor (O_CLOEXEC), or -1 with errno
 * set: EINVAL for something that is not a regular file, ELOOP for a
 * symbolic link unless follow_symlinks. When `source` is not NULL the
 * failure is logged, naming it.
 */
int sb_open_regular(int dir, const char *path, bool follow_symlinks, const char *source);

/* Write all `size` bytes; false with errno set (EIO when no progress). */
bool sb_write_all(int fd, const void *data, size_t size);

/* Read exactly `size` bytes; false with errno set (0 at an early end). */
bool sb_read_all(int fd, void *data, size_t size);

/* Create (or truncate) path and write the bytes; on failure log "path:
 * cannot write the <what>: reason", remove the file and return SB_ERR_IO. */
enum sb_result sb_write_file(const char *path, const void *data, size_t size, const char *what);

/* The whole of `path` (relative to the directory fd `dir`, or AT_FDCWD),
 * at most max_bytes, into a malloc'd buffer (*data, NUL-terminated, *size
 * bytes without the NUL; free it); errors name `source`. A symbolic link is
 * refused unless follow_symlinks (SB_ERR_UNSAFE_PATH), a larger file too
 * (SB_ERR_OUT_OF_RANGE). */
enum sb_result sb_read_file(int dir, const char *path, const char *source, size_t max_bytes, bool follow_symlinks,
                            char **data, size_t *size);

#ifdef __cplusplus
}
#endif

#endif
