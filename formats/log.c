#include "log.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <time.h>
#include <unistd.h>

static enum sb_log_level log_level = SB_LOG_INFO;
static sb_log_sink log_sink;
static void *log_user;
static bool progress_shown; /* a progress line is on the terminal, not yet ended */

void sb_log_set_level(enum sb_log_level level)
{
    log_level = level;
}

void sb_log_set_sink(sb_log_sink sink, void *user)
{
    log_sink = sink;
    log_user = user;
}

void sb_log(enum sb_log_level level, const char *fmt, ...)
{
    if (level > log_level)
        return;
    char buf[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof(buf), fmt, ap);
    va_end(ap);
    if (log_sink) {
        log_sink(log_user, level, buf);
        return;
    }
    static const char *const names[] = {"error", "warning", "info", "debug"};
    if (progress_shown) {
        fputc('\n', stderr);
        progress_shown = false;
    }
    if (level == SB_LOG_INFO)
        fprintf(stderr, "%s\n", buf);
    else
        fprintf(stderr, "skybake: %s: %s\n", names[level], buf);
}

double sb_now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void sb_progress(const char *what, unsigned done, unsigned total)
{
    static double start;
    if (log_sink || log_level < SB_LOG_INFO || !isatty(STDERR_FILENO))
        return;
    if (done == 0) {
        start = sb_now_s();
        return;
    }
    if (!progress_shown && sb_now_s() - start < 1.0)
        return;
    progress_shown = true;
    fprintf(stderr, "\r%s: %u/%u", what, done, total);
    if (done >= total) {
        fputc('\n', stderr);
        progress_shown = false;
    }
    fflush(stderr);
}
