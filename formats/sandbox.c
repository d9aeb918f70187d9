#include "sandbox.h"

#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io.h"
#include "log.h"
#include "skybake_version.h"

extern char **environ;

/* How often a read waiting on the pipe looks whether the helper is gone. */
#define SANDBOX_POLL_MS 50

/* The helper's first argument: a helper of another build (an older
 * install beside a newer build tree) refuses rather than misreads. */
#define SANDBOX_PROTOCOL "skybake-sandbox-2/" SKYBAKE_VERSION

/* The descriptors a helper finds open (SB_SANDBOX_FILE_FD is the file). */
enum { HELPER_REQUEST_FD = 0, HELPER_ANSWER_FD = 3 };

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static bool executable(const char *dir, const char *name, char *path, size_t size)
{
    int n = snprintf(path, size, "%s/%s", dir, name);
    return n > 0 && (size_t)n < size && access(path, X_OK) == 0;
}

/* Where helper `name` is (sandbox.h says in which order it is looked for);
 * false, with the places tried in `tried`, when nowhere. */
static bool find_helper(const char *name, char *path, size_t size, char *tried, size_t tried_size)
{
    if (strchr(name, '/')) {
        snprintf(path, size, "%s", name);
        snprintf(tried, tried_size, "%s", name);
        return access(path, X_OK) == 0;
    }
    const char *env = getenv("SKYBAKE_LIBEXEC_DIR");
    if (env && env[0]) {
        snprintf(tried, tried_size, "%s/%s (SKYBAKE_LIBEXEC_DIR)", env, name);
        return executable(env, name, path, size);
    }
    /* Beside the file this code was loaded from (the library, or a program
     * it is linked into), as the build tree lays them out. */
    char dir[PATH_MAX] = "";
    Dl_info self;
    if (dladdr((void *)sb_sandbox_start, &self) && self.dli_fname && strchr(self.dli_fname, '/')) {
        snprintf(dir, sizeof(dir), "%s", self.dli_fname);
        *strrchr(dir, '/') = '\0';
        static const char *const beside[] = {"", "/../formats", "/../geometry", "/../../formats", "/../../geometry"};
        for (size_t i = 0; i < sizeof(beside) / sizeof(beside[0]); i++) {
            char where[PATH_MAX + 16];
            snprintf(where, sizeof(where), "%s%s", dir, beside[i]);
            if (executable(where, name, path, size))
                return true;
        }
    }
    if (executable(SB_SANDBOX_INSTALL_DIR, name, path, size))
        return true;
    snprintf(tried, tried_size, "%s/%s, and beside %s; set SKYBAKE_LIBEXEC_DIR to its folder", SB_SANDBOX_INSTALL_DIR,
             name, dir[0] ? dir : "the program");
    return false;
}

/* A copy of `fd` numbered above the helper's fixed descriptors, so that
 * every dup2 of the spawn moves a descriptor (and drops close-on-exec). */
static int above_fixed(int fd)
{
    return fd < 0 ? -1 : fcntl(fd, F_DUPFD_CLOEXEC, SB_SANDBOX_FILE_FD + 1);
}

enum sb_result sb_sandbox_start(struct sb_sandbox *box, const struct sb_sandbox_limits *limits, const char *helper,
                                const void *request, size_t size, int file_fd)
{
    static const struct sb_sandbox_limits defaults = {0};
    limits = limits ? limits : &defaults;
    memset(box, 0, sizeof(*box));
    box->fd = -1;
    box->cpu_seconds = limits->cpu_seconds ? limits->cpu_seconds : 30;
    box->wall_seconds = limits->wall_seconds ? limits->wall_seconds : box->cpu_seconds + 30;
    uint64_t address_space = limits->address_space_bytes ? limits->address_space_bytes : 4ull << 30;
    char path[PATH_MAX], tried[PATH_MAX + 256];
    if (!find_helper(helper, path, sizeof(path), tried, sizeof(tried))) {
        sb_error("cannot find the helper program %s: looked at %s", helper, tried);
        return SB_ERR_IO;
    }
    if (size > SB_SANDBOX_MAX_REQUEST) {
        sb_error("%s: a request of %zu bytes (at most %u)", helper, size, SB_SANDBOX_MAX_REQUEST);
        return SB_ERR_TOO_LARGE;
    }
    /* The request in a memory file: no write that could block or raise
     * SIGPIPE in the caller. */
    int request_fd = memfd_create("skybake-request", MFD_CLOEXEC);
    int fds[2] = {-1, -1};
    int answer_write = -1, file = -1, moved_request = -1;
    enum sb_result res = SB_ERR_IO;
    const char *what = "a memory file for its request";
    if (request_fd < 0 || !sb_write_all(request_fd, request, size) || lseek(request_fd, 0, SEEK_SET) != 0)
        goto done;
    what = "a pipe for its answer";
    if (pipe2(fds, O_CLOEXEC) != 0)
        goto done;
    what = "descriptors for it";
    answer_write = above_fixed(fds[1]);
    moved_request = above_fixed(request_fd);
    file = file_fd >= 0 ? above_fixed(file_fd) : -1;
    if (answer_write < 0 || moved_request < 0 || (file_fd >= 0 && file < 0))
        goto done;
    char cpu[32], space[32];
    snprintf(cpu, sizeof(cpu), "%u", box->cpu_seconds);
    snprintf(space, sizeof(space), "%llu", (unsigned long long)address_space);
    char *argv[] = {path, SANDBOX_PROTOCOL, cpu, space, NULL};
    posix_spawn_file_actions_t actions;
    what = "it";
    if (posix_spawn_file_actions_init(&actions) != 0)
        goto done;
    int err = 0;
    err = err ? err : posix_spawn_file_actions_adddup2(&actions, moved_request, HELPER_REQUEST_FD);
    err = err ? err : posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);
    err = err ? err : posix_spawn_file_actions_adddup2(&actions, answer_write, HELPER_ANSWER_FD);
    if (file >= 0)
        err = err ? err : posix_spawn_file_actions_adddup2(&actions, file, SB_SANDBOX_FILE_FD);
    err = err ? err : posix_spawn_file_actions_addclosefrom_np(&actions, SB_SANDBOX_FILE_FD + 1);
    pid_t pid = 0;
    err = err ? err : posix_spawn(&pid, path, &actions, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    if (err) {
        errno = err;
        goto done;
    }
    box->pid = pid;
    box->fd = fds[0];
    fds[0] = -1;
    box->deadline = now_s() + box->wall_seconds;
    res = SB_OK;
done:
    if (res)
        sb_error("cannot start the helper program %s: %s: %s", path, what, strerror(errno));
    int own[] = {request_fd, fds[0], fds[1], answer_write, moved_request, file};
    for (size_t i = 0; i < sizeof(own) / sizeof(own[0]); i++)
        if (own[i] >= 0)
            close(own[i]);
    return res;
}

int sb_sandbox_main(int argc, char **argv, sb_sandbox_fn run)
{
    const char *name = argc > 0 ? argv[0] : "skybake helper";
    if (argc != 4 || strcmp(argv[1], SANDBOX_PROTOCOL) != 0) {
        fprintf(stderr,
                "%s: a helper that skybake's libraries start to parse one file apart from the program reading it; "
                "not for running by hand%s%s (this one is %s)\n",
                name, argc > 1 ? ": started for " : "", argc > 1 ? argv[1] : "", SANDBOX_PROTOCOL);
        return 2;
    }
    char *end;
    unsigned long cpu_seconds = strtoul(argv[2], &end, 10);
    unsigned long long address_space = strtoull(argv[3], &end, 10);
    /* SIGXCPU at the soft limit; the kernel's SIGKILL 5 s later */
    struct rlimit cpu = {cpu_seconds, cpu_seconds + 5};
    setrlimit(RLIMIT_CPU, &cpu);
    /* Beyond what is mapped now, so that AddressSanitizer's shadow
     * (terabytes, reserved before main) does not count; without /proc to
     * say what that is, no limit rather than a wrong one. */
    unsigned long long mapped_pages = 0;
    FILE *statm = fopen("/proc/self/statm", "r");
    if (statm) {
        if (fscanf(statm, "%llu", &mapped_pages) != 1)
            mapped_pages = 0;
        fclose(statm);
    }
    if (mapped_pages) {
        rlim_t limit = (rlim_t)(mapped_pages * (unsigned long long)sysconf(_SC_PAGESIZE) + address_space);
        struct rlimit as = {limit, limit};
        setrlimit(RLIMIT_AS, &as);
    }
    signal(SIGPIPE, SIG_DFL);
    struct stat st;
    if (fstat(HELPER_REQUEST_FD, &st) != 0 || st.st_size < 0 || st.st_size > SB_SANDBOX_MAX_REQUEST) {
        fprintf(stderr, "%s: no request on its standard input\n", name);
        return 2;
    }
    size_t size = (size_t)st.st_size;
    char *request = malloc(size + 1);
    size_t got = 0;
    while (request && got < size) {
        ssize_t n = read(HELPER_REQUEST_FD, request + got, size - got);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        got += (size_t)n;
    }
    if (!request || got != size) {
        fprintf(stderr, "%s: cannot read its request\n", name);
        free(request);
        return 2;
    }
    int status = run(HELPER_ANSWER_FD, request, size);
    free(request);
    return status;
}

struct capture {
    char *message;
    size_t size;
};

static void capture_first(void *user, enum sb_log_level level, const char *message)
{
    struct capture *c = user;
    if (level <= SB_LOG_WARN && c->size && !c->message[0])
        snprintf(c->message, c->size, "%s", message);
    if (level > SB_LOG_WARN)
        fprintf(stderr, "%s\n", message);
}

void sb_sandbox_capture_log(char *message, size_t size)
{
    static struct capture capture; /* one per process: the helper's */
    capture = (struct capture){message, size};
    if (size)
        message[0] = '\0';
    sb_log_set_sink(capture_first, &capture);
}

/* Whether the helper has exited, leaving it to be reaped. */
static bool helper_gone(const struct sb_sandbox *box)
{
    siginfo_t info;
    memset(&info, 0, sizeof(info));
    if (waitid(P_PID, (id_t)box->pid, &info, WEXITED | WNOHANG | WNOWAIT) != 0)
        return errno == ECHILD;
    return info.si_pid == box->pid;
}

bool sb_sandbox_read(struct sb_sandbox *box, void *data, size_t size)
{
    char *p = data;
    while (size) {
        double left = box->deadline - now_s();
        if (left <= 0) {
            box->late = true;
            return false;
        }
        int wait_ms = left * 1e3 < SANDBOX_POLL_MS ? (int)(left * 1e3) + 1 : SANDBOX_POLL_MS;
        struct pollfd pfd = {.fd = box->fd, .events = POLLIN};
        int ready = poll(&pfd, 1, wait_ms);
        if (ready < 0 && errno != EINTR)
            return false;
        if (ready <= 0) {
            /* Nothing yet. A helper that has exited wrote all it will write
             * before it did, so an empty pipe now stays empty, even where
             * some other process still holds the write end. */
            if (helper_gone(box) && poll(&pfd, 1, 0) <= 0)
                return false;
            continue;
        }
        ssize_t n = read(box->fd, p, size);
        if (n < 0 && (errno == EINTR || errno == EAGAIN))
            continue;
        if (n <= 0)
            return false;
        p += n;
        size -= (size_t)n;
    }
    return true;
}

void sb_sandbox_finish(struct sb_sandbox *box, char *why, size_t why_size)
{
    if (box->pid <= 0) {
        if (why && why_size)
            snprintf(why, why_size, "never started");
        return;
    }
    bool running = !helper_gone(box);
    /* The pipe's end can come just before the child is reapable: give one
     * whose answer stopped short a moment to end on its own, for its reason. */
    for (int i = 0; running && why && !box->late && i < 200; i++) {
        nanosleep(&(struct timespec){.tv_nsec = 10 * 1000 * 1000}, NULL);
        running = !helper_gone(box);
    }
    if (running)
        kill(box->pid, SIGKILL); /* done or stuck: either way it has nothing more to say */
    int status = 0;
    struct rusage usage;
    memset(&usage, 0, sizeof(usage));
    while (wait4(box->pid, &status, 0, &usage) < 0 && errno == EINTR)
        ;
    if (box->fd >= 0)
        close(box->fd);
    double cpu = (double)usage.ru_utime.tv_sec + (double)usage.ru_stime.tv_sec +
                 ((double)usage.ru_utime.tv_usec + (double)usage.ru_stime.tv_usec) * 1e-6;
    if (why && why_size) {
        if (box->late)
            snprintf(why, why_size, "did not answer within %u s (wall clock; it had used %.1f s of CPU time)",
                     box->wall_seconds, cpu);
        else if (running)
            snprintf(why, why_size, "closed its answer early and was stopped");
        else if (WIFSIGNALED(status) &&
                 (WTERMSIG(status) == SIGXCPU || (WTERMSIG(status) == SIGKILL && cpu >= box->cpu_seconds)))
            snprintf(why, why_size, "ran past its %u s of CPU time", box->cpu_seconds);
        else if (WIFSIGNALED(status))
            snprintf(why, why_size, "crashed (%s)", strsignal(WTERMSIG(status)));
        else if (WEXITSTATUS(status))
            snprintf(why, why_size, "failed (exit status %d)", WEXITSTATUS(status));
        else
            snprintf(why, why_size, "exited before sending its whole answer");
    }
    box->status = status;
    box->reaped = true;
    box->pid = 0;
    box->fd = -1;
}
