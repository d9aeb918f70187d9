#include "log.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static enum sb_log_level log_level = SB_LOG_INFO;
static sb_log_sink log_sink;
static void *log_user;
static const char *log_program = "skybake"; /* sb_log_set_program */
static bool progress_shown;                 /* a progress line is on the terminal, not yet ended */
static bool status_shown;                   /* a status line is on the terminal */

static bool terminal_lines(void)
{
    return !log_sink && log_level >= SB_LOG_INFO && isatty(STDERR_FILENO);
}

/* Clear the status line, if one is shown; the cursor is left at its start. */
static void clear_status(void)
{
    if (status_shown)
        fputs("\r\033[K", stderr);
    status_shown = false;
}

void sb_log_set_program(const char *name)
{
    log_program = name;
}

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
    clear_status();
    if (progress_shown) {
        fputc('\n', stderr);
        progress_shown = false;
    }
    if (level == SB_LOG_INFO)
        fprintf(stderr, "%s\n", buf);
    else
        fprintf(stderr, "%s: %s: %s\n", log_program, names[level], buf);
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
    if (!terminal_lines())
        return;
    if (done == 0) {
        start = sb_now_s();
        return;
    }
    if (!progress_shown && sb_now_s() - start < 1.0)
        return;
    progress_shown = true;
    status_shown = false; /* the line below overwrites it */
    fprintf(stderr, "\r%s: %u/%u\033[K", what, done, total);
    if (done >= total) {
        fputc('\n', stderr);
        progress_shown = false;
    }
    fflush(stderr);
}

/* The status lines, the current one last; [0] is sb_status's. */
#define STATUS_DEPTH 5
static char status_text[STATUS_DEPTH][80];
static int status_depth; /* lines held above [0] */

static void show_status(void)
{
    if (!terminal_lines())
        return;
    if (progress_shown) { /* a progress line not ended: keep it */
        fputc('\n', stderr);
        progress_shown = false;
    }
    clear_status();
    const char *text = status_text[status_depth];
    if (text[0]) {
        fputs(text, stderr);
        status_shown = true;
    }
    fflush(stderr);
}

/* One line of a narrow terminal, else the clear misses its start: cut at a
 * character's start, and say so. */
static void format_status(char out[80], const char *fmt, va_list ap)
{
    int n = vsnprintf(out, 80, fmt, ap);
    if (n >= 80) {
        size_t end = 80 - 4;
        while (end > 0 && ((unsigned char)out[end] & 0xc0) == 0x80)
            end--;
        memcpy(&out[end], "...", 4);
    }
}

void sb_status(const char *fmt, ...)
{
    status_text[status_depth][0] = '\0';
    if (fmt) {
        va_list ap;
        va_start(ap, fmt);
        format_status(status_text[status_depth], fmt, ap);
        va_end(ap);
    }
    show_status();
}

void sb_status_begin(const char *fmt, ...)
{
    if (status_depth + 1 < STATUS_DEPTH)
        status_depth++;
    va_list ap;
    va_start(ap, fmt);
    format_status(status_text[status_depth], fmt, ap);
    va_end(ap);
    show_status();
}

void sb_status_end(void)
{
    status_text[status_depth][0] = '\0';
    if (status_depth > 0)
        status_depth--;
    show_status();
}
