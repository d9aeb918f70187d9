#include "sandbox.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "log.h"

/* How often a read waiting on the pipe looks whether the child is gone. */
#define SANDBOX_POLL_MS 50

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

enum sb_result sb_sandbox_start(struct sb_sandbox *box, const struct sb_sandbox_limits *limits, sb_sandbox_fn fn,
                                void *user)
{
    static const struct sb_sandbox_limits defaults = {0};
    limits = limits ? limits : &defaults;
    memset(box, 0, sizeof(*box));
    box->fd = -1;
    box->cpu_seconds = limits->cpu_seconds ? limits->cpu_seconds : 30;
    box->wall_seconds = limits->wall_seconds ? limits->wall_seconds : box->cpu_seconds + 30;
    uint64_t address_space = limits->address_space_bytes ? limits->address_space_bytes : 4ull << 30;
    int fds[2];
    /* Close-on-exec: a program some library spawns (a symbolizer, a
     * helper) must not hold the write end past the child. */
    if (pipe2(fds, O_CLOEXEC) != 0) {
        sb_error("cannot make a pipe for a parsing process: %s", strerror(errno));
        return SB_ERR_IO;
    }
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        sb_error("cannot start a parsing process: %s", strerror(errno));
        close(fds[0]);
        close(fds[1]);
        return SB_ERR_IO;
    }
    if (pid == 0) {
        close(fds[0]);
        /* SIGXCPU at the soft limit; the kernel's SIGKILL 5 s later */
        struct rlimit cpu = {box->cpu_seconds, box->cpu_seconds + 5};
        setrlimit(RLIMIT_CPU, &cpu);
        /* Beyond what is mapped now, so that AddressSanitizer's shadow
         * (terabytes, reserved before the limit) does not count; without
         * /proc to say what that is, no limit rather than a wrong one. */
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
        _exit(fn(fds[1], user));
    }
    close(fds[1]);
    box->pid = pid;
    box->fd = fds[0];
    box->deadline = now_s() + box->wall_seconds;
    return SB_OK;
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
    static struct capture capture; /* one per process: the child's */
    capture = (struct capture){message, size};
    if (size)
        message[0] = '\0';
    sb_log_set_sink(capture_first, &capture);
}

/* Whether the child has exited, leaving it to be reaped. */
static bool child_gone(const struct sb_sandbox *box)
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
            /* Nothing yet. A child that has exited wrote all it will write
             * before it did, so an empty pipe now stays empty, even where
             * some other process still holds the write end. */
            if (child_gone(box) && poll(&pfd, 1, 0) <= 0)
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
    bool running = !child_gone(box);
    /* The pipe's end can come just before the child is reapable: give one
     * whose answer stopped short a moment to end on its own, for its reason. */
    for (int i = 0; running && why && !box->late && i < 200; i++) {
        nanosleep(&(struct timespec){.tv_nsec = 10 * 1000 * 1000}, NULL);
        running = !child_gone(box);
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
