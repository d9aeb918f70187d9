/*
 * A tiny test harness: CHECK records a failure with file:line and goes on;
 * main returns 0, 1 (failures) or 77 (skip, e.g. no Vulkan device).
 * parallel_for spreads independent fp64 reference work over the cores.
 */
#ifndef SB_TEST_HARNESS_H
#define SB_TEST_HARNESS_H

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static int test_failures;
static int test_checks;

#define CHECK(cond, ...)                                                                                               \
    do {                                                                                                               \
        test_checks++;                                                                                                 \
        if (!(cond)) {                                                                                                 \
            test_failures++;                                                                                           \
            fprintf(stderr, "%s:%d: FAILED: %s: ", __FILE__, __LINE__, #cond);                                         \
            fprintf(stderr, __VA_ARGS__);                                                                              \
            fprintf(stderr, "\n");                                                                                     \
        }                                                                                                              \
    } while (0)

#define TEST_SKIP 77

static inline int test_finish(const char *name)
{
    printf("%s: %d checks, %d failed\n", name, test_checks, test_failures);
    return test_failures ? 1 : 0;
}

struct parallel_job {
    void (*fn)(void *user, int index);
    void *user;
    int count;
    int next;
    pthread_mutex_t lock;
};

static void *parallel_worker(void *arg)
{
    struct parallel_job *job = arg;
    for (;;) {
        pthread_mutex_lock(&job->lock);
        int i = job->next++;
        pthread_mutex_unlock(&job->lock);
        if (i >= job->count)
            return NULL;
        job->fn(job->user, i);
    }
}

static inline void parallel_for(int count, void (*fn)(void *user, int index), void *user)
{
    struct parallel_job job = {fn, user, count, 0, PTHREAD_MUTEX_INITIALIZER};
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    if (n < 1)
        n = 1;
    if (n > 16)
        n = 16;
    pthread_t threads[16];
    for (long t = 0; t < n; t++)
        pthread_create(&threads[t], NULL, parallel_worker, &job);
    for (long t = 0; t < n; t++)
        pthread_join(threads[t], NULL);
}

#endif
