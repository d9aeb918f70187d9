#include "parallel.h"

#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>
#include <unistd.h>

/*
 * A pool of threads started on the first parallel_for and kept (started
 * again when the thread count changes): starting 16 threads a call cost
 * the BVH build tens of milliseconds over its hundreds of calls. A call
 * made while the pool works (from one of its jobs, or from another
 * thread) runs on the calling thread alone.
 */
static struct {
    pthread_mutex_t lock;
    pthread_cond_t work, done;
    pthread_t threads[SB_PARALLEL_MAX_THREADS];
    int started;     /* threads in the pool, besides the caller */
    bool busy, quit; /* a job is posted; the pool is being stopped */
    unsigned generation;
    /* the job */
    void (*fn)(void *user, int index);
    void *user;
    int count, next, running;
} pool = {.lock = PTHREAD_MUTEX_INITIALIZER, .work = PTHREAD_COND_INITIALIZER, .done = PTHREAD_COND_INITIALIZER};

static int threads_set;

int sb_parallel_threads(void)
{
    if (threads_set)
        return threads_set;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > SB_PARALLEL_MAX_THREADS ? SB_PARALLEL_MAX_THREADS : (int)n;
}

/* Take indices of the posted job until none is left; called with the lock held. */
static void run_job(void)
{
    while (pool.next < pool.count) {
        int i = pool.next++;
        pthread_mutex_unlock(&pool.lock);
        pool.fn(pool.user, i);
        pthread_mutex_lock(&pool.lock);
    }
}

/* arg: the generation when the thread was made. A thread made for a job
 * may first take the lock after the job was posted; reading the generation
 * then would take the job for one already seen, and leave it to the
 * caller alone. */
static void *worker(void *arg)
{
    unsigned seen = (unsigned)(uintptr_t)arg;
    pthread_mutex_lock(&pool.lock);
    for (;;) {
        while (!pool.quit && pool.generation == seen)
            pthread_cond_wait(&pool.work, &pool.lock);
        if (pool.quit)
            break;
        seen = pool.generation;
        pool.running++;
        run_job();
        if (--pool.running == 0)
            pthread_cond_signal(&pool.done);
    }
    pthread_mutex_unlock(&pool.lock);
    return NULL;
}

/* Stop the pool's threads; called with the lock held and no job posted. */
static void stop_pool(void)
{
    pool.quit = true;
    pthread_cond_broadcast(&pool.work);
    pthread_mutex_unlock(&pool.lock);
    for (int t = 0; t < pool.started; t++)
        pthread_join(pool.threads[t], NULL);
    pthread_mutex_lock(&pool.lock);
    pool.started = 0;
    pool.quit = false;
}

void sb_parallel_set_threads(int n)
{
    pthread_mutex_lock(&pool.lock);
    threads_set = n < 0 ? 0 : n > SB_PARALLEL_MAX_THREADS ? SB_PARALLEL_MAX_THREADS : n;
    if (!pool.busy && pool.started && pool.started != sb_parallel_threads() - 1)
        stop_pool();
    pthread_mutex_unlock(&pool.lock);
}

void sb_parallel_for(int count, void (*fn)(void *user, int index), void *user)
{
    pthread_mutex_lock(&pool.lock);
    int want = sb_parallel_threads() - 1;
    if (pool.busy || count <= 1 || want < 1) { /* nested, concurrent, or nothing to share */
        pthread_mutex_unlock(&pool.lock);
        for (int i = 0; i < count; i++)
            fn(user, i);
        return;
    }
    if (pool.started != want) {
        if (pool.started)
            stop_pool();
        while (pool.started < want &&
               pthread_create(&pool.threads[pool.started], NULL, worker, (void *)(uintptr_t)pool.generation) == 0)
            pool.started++;
    }
    pool.busy = true;
    pool.fn = fn;
    pool.user = user;
    pool.count = count;
    pool.next = 0;
    pool.running = 1; /* this thread */
    pool.generation++;
    pthread_cond_broadcast(&pool.work);
    run_job();
    pool.running--;
    while (pool.running > 0)
        pthread_cond_wait(&pool.done, &pool.lock);
    pool.busy = false;
    pthread_mutex_unlock(&pool.lock);
}
