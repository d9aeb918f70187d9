/*
 * A child process that parses untrusted bytes for us.
 *
 * assimp and OpenVDB are not hardened against hostile files: on this
 * machine a PLY header made assimp loop for ever, and a cut VDB made
 * OpenVDB allocate 20 GB. So their parsers run in a forked child under a
 * CPU-time limit and an address-space limit; the child writes its answer
 * into a pipe, and the parent reads it with a wall-clock deadline, checking
 * every count it receives. A hang, a crash, a limit or a child that exits
 * without its whole answer becomes an error naming why, never a hang of the
 * parent: the parent notices the child's exit even where another process
 * still holds the pipe's write end.
 *
 * Linux (fork, pipes, rlimits, /proc). Thread-safe: a child forked by
 * another thread may inherit this one's pipe, which is why the end of an
 * answer is told by the child's exit and not by the pipe's end alone.
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
    unsigned cpu_seconds; /* the child's CPU time [30] */
    /* The address space the child may map beyond what the process has
     * mapped at the fork (read from /proc; none where it cannot be) [4 GiB]. */
    uint64_t address_space_bytes;
    unsigned wall_seconds; /* the whole exchange, from the fork [cpu_seconds + 30] */
};

/* In the child: write the answer to `fd` and return the exit status. */
typedef int (*sb_sandbox_fn)(int fd, void *user);

/* Caller-owned; sb_sandbox_start fills it, sb_sandbox_finish ends it. */
struct sb_sandbox {
    pid_t pid;
    int fd;          /* the pipe's read end */
    double deadline; /* CLOCK_MONOTONIC seconds */
    unsigned cpu_seconds, wall_seconds;
    bool late;   /* a read ran past the deadline */
    bool reaped; /* status holds the child's wait status */
    int status;
};

/*
 * Fork a child that runs fn(fd, user) under `limits` (NULL: the defaults)
 * and exits with its return value (_exit: no atexit handler of the parent
 * runs twice). Returns SB_OK, or SB_ERR_IO when no pipe or process can be
 * made (logged).
 */
enum sb_result sb_sandbox_start(struct sb_sandbox *box, const struct sb_sandbox_limits *limits, sb_sandbox_fn fn,
                                void *user);

/*
 * In the child: keep the first warning or error logged from now on in
 * message[size] (NUL-terminated, for the answer), and print the lower
 * levels to stderr as usual.
 */
void sb_sandbox_capture_log(char *message, size_t size);

/*
 * Read exactly `size` bytes of the child's answer. False at the pipe's end,
 * once the child has exited with nothing more in the pipe, or past the
 * deadline; sb_sandbox_finish then says why.
 */
bool sb_sandbox_read(struct sb_sandbox *box, void *data, size_t size);

/*
 * Kill the child if it is still running, reap it and close the pipe. When
 * `why` is not NULL, it receives a phrase for an error message saying how
 * the child ended ("ran past its 30 s of CPU time", "crashed (Segmentation
 * fault)", "exited before sending its whole answer", ...), for a caller
 * whose read failed. Accepts a box that was never started (pid 0).
 */
void sb_sandbox_finish(struct sb_sandbox *box, char *why, size_t why_size);

#ifdef __cplusplus
}
#endif

#endif
