/*
 * A helper process that parses untrusted bytes for us.
 *
 * assimp and OpenVDB are not hardened against hostile files: on this
 * machine a PLY header made assimp loop for ever, and a cut VDB made
 * OpenVDB allocate 20 GB. So their parsers run only in small helper
 * programs (skybake-import-mesh, skybake-vdb), started for each file
 * under a CPU-time limit and an address-space limit; the helper writes its
 * answer into a pipe, and the parent reads it with a wall-clock deadline,
 * checking every count it receives. A hang, a crash, a limit or a helper
 * that exits without its whole answer becomes an error naming why, never a
 * hang of the parent: the parent notices the helper's exit even where
 * another process still holds the pipe's write end.
 *
 * The helper is a new program (posix_spawn), not a fork of the caller: a
 * forked copy of a threaded process (an engine, the baker with its Vulkan
 * driver's threads, a library's thread pool) holds whatever locks those
 * threads held at the fork, and its first malloc or TBB call could wait on
 * them for ever (tests/test_formats.c's "threads at the start" case).
 *
 * Where the helpers are: in $SKYBAKE_LIBEXEC_DIR when set; else beside the
 * file this code was loaded from (the library, or a program linked with
 * it) as the build tree lays them out (its folder, or formats/ and
 * geometry/ one or two folders up); else the installed ones
 * (libexecdir/skybake).
 *
 * Linux (posix_spawn, memfd, pipes, rlimits, /proc). Thread-safe.
 */
#ifndef SB_SANDBOX_H
#define SB_SANDBOX_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

#include "result.h"

#ifdef __cplusplus
extern "C" {
#endif

struct sb_sandbox_limits {
    unsigned cpu_seconds; /* the helper's CPU time [30] */
    /* The address space the helper may map beyond what it has mapped when
     * it starts (read from /proc; none where it cannot be) [4 GiB]. */
    uint64_t address_space_bytes;
    unsigned wall_seconds; /* the whole exchange, from the start [cpu_seconds + 30] */
};

/* A helper's task: answer `request` (size bytes) on `fd` and return the
 * exit status. The file given to sb_sandbox_start, if any, is open on
 * SB_SANDBOX_FILE_FD. */
typedef int (*sb_sandbox_fn)(int fd, const void *request, size_t size);

#define SB_SANDBOX_FILE_FD 4
#define SB_SANDBOX_MAX_REQUEST (1u << 20)

/* Caller-owned; sb_sandbox_start fills it, sb_sandbox_finish ends it. */
struct sb_sandbox {
    pid_t pid;
    int fd;          /* the pipe's read end */
    double deadline; /* CLOCK_MONOTONIC seconds */
    unsigned cpu_seconds, wall_seconds;
    bool late;   /* a read ran past the deadline */
    bool reaped; /* status holds the helper's wait status */
    int status;
};

/*
 * Start `helper` (a name looked up as said above, or a path holding a '/')
 * under `limits` (NULL: the defaults), with `request` (size bytes, at most
 * SB_SANDBOX_MAX_REQUEST) for its task and `file_fd` (-1: none) open on
 * SB_SANDBOX_FILE_FD. Its stdout and stderr are the caller's stderr.
 * Returns SB_OK, or SB_ERR_IO when the helper cannot be found or started
 * (logged, naming where it was looked for).
 */
enum sb_result sb_sandbox_start(struct sb_sandbox *box, const struct sb_sandbox_limits *limits, const char *helper,
                                const void *request, size_t size, int file_fd);

/*
 * A helper program's main: checks that the library that started it is of
 * the same build, takes its limits, reads the request and returns
 * run(...)'s status. A program run by hand is told what it is for (exit 2).
 */
int sb_sandbox_main(int argc, char **argv, sb_sandbox_fn run);

/*
 * In the helper: keep the first warning or error logged from now on in
 * message[size] (NUL-terminated, for the answer), and print the lower
 * levels to stderr as usual.
 */
void sb_sandbox_capture_log(char *message, size_t size);

/*
 * Read exactly `size` bytes of the helper's answer. False at the pipe's end,
 * once the helper has exited with nothing more in the pipe, or past the
 * deadline; sb_sandbox_finish then says why.
 */
bool sb_sandbox_read(struct sb_sandbox *box, void *data, size_t size);

/*
 * Kill the helper if it is still running, reap it and close the pipe. When
 * `why` is not NULL, it receives a phrase for an error message saying how
 * the helper ended ("ran past its 30 s of CPU time", "crashed (Segmentation
 * fault)", "exited before sending its whole answer", ...), for a caller
 * whose read failed. Accepts a box that was never started (pid 0).
 */
void sb_sandbox_finish(struct sb_sandbox *box, char *why, size_t why_size);

#ifdef __cplusplus
}
#endif

#endif
