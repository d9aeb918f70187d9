/*
 * Arrays that grow by doubling, for the libraries' lists of things made
 * one at a time (a BVH build's tasks, a context's pipelines).
 */
#ifndef SB_ARRAY_H
#define SB_ARRAY_H

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>

/* Room in *array (of `count` items of `size` bytes, room for *capacity)
 * for one more: doubled (64 at first) by realloc when full. False, the
 * array unchanged, when the memory is not there or the count would pass
 * 2^31. */
static inline bool sb_array_grow(void **array, uint32_t count, uint32_t *capacity, size_t size)
{
    if (count < *capacity)
        return true;
    if (*capacity > UINT32_MAX / 2)
        return false;
    uint32_t more = *capacity ? 2 * *capacity : 64;
    void *grown = realloc(*array, (size_t)more * size);
    if (!grown)
        return false;
    *array = grown;
    *capacity = more;
    return true;
}

#endif
