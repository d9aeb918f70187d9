/*
 * splitmix64 (Steele, Lea and Flood 2014): a 64-bit generator whose state is
 * a counter, for seeds and for the few random numbers references and
 * scatterings need; the same sequence on every platform.
 */
#ifndef SB_FORMATS_SPLITMIX_H
#define SB_FORMATS_SPLITMIX_H

#include <stdint.h>

static inline uint64_t sb_splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1), 53 bits. */
static inline double sb_splitmix_uniform(uint64_t *state)
{
    return (double)(sb_splitmix64(state) >> 11) * 0x1.0p-53;
}

#endif
