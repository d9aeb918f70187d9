/*
 * geometry/parallel.c: every index runs once, and the pool's threads share
 * the work from the first call of a process on (a thread made for a job
 * must not miss it: until 2026-11-29 the first call ran on the caller
 * alone, which made sky-error a one-core run).
 */
#include <pthread.h>
#include <stdatomic.h>
#include <time.h>

#include "harness.h"
#include "parallel.h"

#define COUNT 1000

struct job {
    atomic_int runs[COUNT];
    pthread_t first;   /* the thread that ran index 0 */
    atomic_int others; /* indices run by a thread other than index 0's */
    atomic_bool first_set;
};

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void run(void *user, int index)
{
    struct job *job = user;
    atomic_fetch_add(&job->runs[index], 1);
    if (index == 0) {
        job->first = pthread_self();
        atomic_store(&job->first_set, true);
        /* wait (at most 10 s) for another thread to take an index */
        for (double t0 = now_s(); !atomic_load(&job->others) && now_s() - t0 < 10.0;)
            nanosleep(&(struct timespec){0, 1000000}, NULL);
        return;
    }
    while (!atomic_load(&job->first_set))
        ;
    if (!pthread_equal(pthread_self(), job->first))
        atomic_fetch_add(&job->others, 1);
}

static void check_call(const char *what)
{
    static struct job job;
    for (int i = 0; i < COUNT; i++)
        atomic_store(&job.runs[i], 0);
    atomic_store(&job.others, 0);
    atomic_store(&job.first_set, false);
    sb_parallel_for(COUNT, run, &job);
    int wrong = 0;
    for (int i = 0; i < COUNT; i++)
        wrong += atomic_load(&job.runs[i]) != 1;
    CHECK(wrong == 0, "%s: %d of %d indices not run exactly once", what, wrong, COUNT);
    CHECK(atomic_load(&job.others) > 0, "%s: no index ran beside index 0 (the pool's threads missed the job)", what);
}

int main(void)
{
    sb_parallel_set_threads(2);
    check_call("the first call");
    check_call("the second call");
    sb_parallel_set_threads(3);
    check_call("the first call after the thread count changed");
    return test_finish("parallel");
}
