/*
 * One logger for every tier. Messages go to stderr as "skybake: LEVEL: text"
 * unless a sink is installed (tests capture messages this way). Not thread
 * safe: configure it before starting threads.
 */
#ifndef SB_LOG_H
#define SB_LOG_H

enum sb_log_level {
    SB_LOG_ERROR,
    SB_LOG_WARN,
    SB_LOG_INFO,
    SB_LOG_DEBUG,
};

typedef void (*sb_log_sink)(void *user, enum sb_log_level level, const char *message);

/* Messages above `level` are dropped. Default: SB_LOG_INFO. */
void sb_log_set_level(enum sb_log_level level);
/* Replace the stderr sink; NULL restores it. */
void sb_log_set_sink(sb_log_sink sink, void *user);
/* The program that the stderr sink names before each message (a static
 * string). Default: "skybake". */
void sb_log_set_program(const char *name);

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
void sb_log(enum sb_log_level level, const char *fmt, ...);

/* Seconds on a monotonic clock (CLOCK_MONOTONIC), for wall times and progress. */
double sb_now_s(void);

/*
 * Progress of long work: "what: done/total" rewritten in place on stderr,
 * first shown once a second has passed since the call with done 0, ended by
 * a newline with done == total. Silent when stderr is not a terminal, while
 * a sink is installed, or with the level below SB_LOG_INFO (quiet, --json).
 */
void sb_progress(const char *what, unsigned done, unsigned total);

/*
 * What the program is doing now ("sky_visibility (3 of 5 products)"), in
 * place on stderr until the next status, progress or log line replaces
 * it; NULL clears it. For steps that may take more than a second and
 * report nothing else. The same silence as sb_progress.
 * sb_status_begin shows a step inside the current one ("loading
 * world.obj", "BVH: 1002528 triangles"); sb_status_end shows the current
 * one again. They nest four deep.
 */
#if defined(__GNUC__)
__attribute__((format(printf, 1, 2)))
#endif
void sb_status(const char *fmt, ...);
#if defined(__GNUC__)
__attribute__((format(printf, 1, 2)))
#endif
void sb_status_begin(const char *fmt, ...);
void sb_status_end(void);

#define sb_error(...) sb_log(SB_LOG_ERROR, __VA_ARGS__)
#define sb_warn(...) sb_log(SB_LOG_WARN, __VA_ARGS__)
#define sb_info(...) sb_log(SB_LOG_INFO, __VA_ARGS__)
#define sb_debug(...) sb_log(SB_LOG_DEBUG, __VA_ARGS__)

#endif
