#include "log.h"

#include <stdarg.h>
#include <stdio.h>

static enum sb_log_level log_level = SB_LOG_INFO;
static sb_log_sink log_sink;
static void *log_user;

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
    if (level == SB_LOG_INFO)
        fprintf(stderr, "%s\n", buf);
    else
        fprintf(stderr, "skybake: %s: %s\n", names[level], buf);
}
