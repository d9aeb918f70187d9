/*
 * Spread independent work over the cores: fn(user, i) for every i in
 * [0, count), on up to sb_parallel_threads() threads. Results must not
 * depend on the order or the thread count, so each index writes its own
 * slot. The indices are handed out in increasing order, one at a time to
 * each thread, so a job may wait for every lower index to reach some point
 * (the EXR writer's chunks wait for the one before them to be written):
 * each lower index is then running or done. Used by the BVH build, the
 * fp64 references, the EXR writers and the tests.
 */
#ifndef SB_PARALLEL_H
#define SB_PARALLEL_H

#define SB_PARALLEL_MAX_THREADS 64

void sb_parallel_for(int count, void (*fn)(void *user, int index), void *user);

/* How many threads sb_parallel_for uses: set_threads(0), the default, is
 * every online core (at most SB_PARALLEL_MAX_THREADS); n > 0 is n. The
 * setting is the process's; change it only while no parallel_for runs. */
void sb_parallel_set_threads(int n);
int sb_parallel_threads(void);

#endif
