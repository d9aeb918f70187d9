#include "parallel.h"

#include <pthread.h>
#include <unistd.h>

struct job {
    void (*fn)(void *user, int index);
    void *user;
    int count;
    int next;
    pthread_mutex_t lock;
};

static void *worker(void *arg)
{
    struct job *job = arg;
    for (;;) {
        pthread_mutex_lock(&job->lock);
        int i = job->next++;
        pthread_mutex_unlock(&job->lock);
        if (i >= job->count)
            return NULL;
        job->fn(job->user, i);
    }
}

void sb_parallel_for(int count, void (*fn)(void *user, int index), void *user)
{
    struct job job = {fn, user, count, 0, PTHREAD_MUTEX_INITIALIZER};
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    n = n < 1 ? 1 : n > 16 ? 16 : n;
    if (n > count)
        n = count;
    pthread_t threads[16];
    long started = 0;
    for (long t = 0; t < n; t++)
        if (pthread_create(&threads[t], NULL, worker, &job) == 0)
            started++;
    if (!started) /* no threads to be had: do the work here */
        worker(&job);
    for (long t = 0; t < started; t++)
        pthread_join(threads[t], NULL);
}
