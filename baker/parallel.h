/*
 * Spread independent work (fp64 references, mostly) over the cores:
 * fn(user, i) for every i in [0, count), in any order, on up to 16 threads.
 * Results must not depend on the order, so each index writes its own slot.
 */
#ifndef SB_BAKER_PARALLEL_H
#define SB_BAKER_PARALLEL_H

void sb_parallel_for(int count, void (*fn)(void *user, int index), void *user);

#endif
