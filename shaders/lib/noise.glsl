/*
 * Tileable cloud noise (baker/clouds.h has the definitions and the recipes
 * of each product's channels; baker/clouds_ref.c is the CPU reference this
 * must match bit for bit). Only integer operations and fp32 add, subtract,
 * multiply and compare: Vulkan rounds those correctly on every device,
 * while division, sqrt and the transcendentals may differ by ulps between
 * drivers. Every result is `precise`, so that no multiply and add fuse.
 */
#ifndef SB_NOISE_GLSL
#define SB_NOISE_GLSL

#include "config.h"

/* Jarzynski and Olano's pcg3d: three 32-bit hashes of three integers. */
uvec3 noise_hash(uvec3 v)
{
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return v;
}

/* The lattice point c, in [-1, period], wrapped into [0, period), of a
 * seeded noise. */
uvec3 noise_lattice(ivec3 c, int period, uint seed)
{
    /* no integer division: llvmpipe has no vector form of it */
    ivec3 w = mix(c, c - period, greaterThanEqual(c, ivec3(period)));
    w = mix(w, w + period, lessThan(w, ivec3(0)));
    return noise_hash(uvec3(w) + uvec3(0u, 0u, seed * 0x9E3779B9u));
}

/* [0, 1) from the top 24 bits: exact in fp32. */
vec3 noise_unit(uvec3 h)
{
    return vec3(h >> 8u) * (1.0 / 16777216.0);
}

/* sqrt(x) for x in [0, 4] by Newton's iteration for 1/sqrt from an integer
 * first guess: multiplies and subtractions only. */
float noise_sqrt(float x)
{
    if (x <= 0.0)
        return 0.0;
    precise float y = uintBitsToFloat(0x5F375A86u - (floatBitsToUint(x) >> 1u));
    for (int i = 0; i < 4; i++) {
        precise float xyy = x * y * y;
        y = y * (1.5 - 0.5 * xyy);
    }
    precise float s = x * y;
    return s;
}

/* Perlin's gradient noise with an integer period in each axis, in [-1, 1]:
 * gradients among the 12 cube edge directions, quintic fade. */
float noise_perlin(vec3 p, int period, uint seed)
{
    precise vec3 x = p * float(period);
    vec3 cf = floor(x);
    ivec3 c = ivec3(cf);
    precise vec3 f = x - cf;
    precise vec3 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    float corner[8];
    for (int k = 0; k < 8; k++) {
        ivec3 o = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        uint h = ((noise_lattice(c + o, period, seed).x >> 8u) * 12u) >> 24u; /* in [0, 12) */
        precise vec3 d = f - vec3(o);
        /* (+-1, +-1, 0), (+-1, 0, +-1), (0, +-1, +-1) */
        float s0 = (h & 1u) != 0u ? -1.0 : 1.0, s1 = (h & 2u) != 0u ? -1.0 : 1.0;
        uint axis = h >> 2u;
        precise float g = axis == 0u ? s0 * d.x + s1 * d.y : axis == 1u ? s0 * d.x + s1 * d.z : s0 * d.y + s1 * d.z;
        corner[k] = g;
    }
    precise float x00 = corner[0] + u.x * (corner[1] - corner[0]);
    precise float x10 = corner[2] + u.x * (corner[3] - corner[2]);
    precise float x01 = corner[4] + u.x * (corner[5] - corner[4]);
    precise float x11 = corner[6] + u.x * (corner[7] - corner[6]);
    precise float y0 = x00 + u.y * (x10 - x00);
    precise float y1 = x01 + u.y * (x11 - x01);
    precise float n = y0 + u.z * (y1 - y0);
    return n;
}

/* 1 / (1 + 1/2 + ... + 2^(1-n)), rounded to fp32 here and in clouds_ref.c
 * alike (a division would not round alike on every device). */
const float noise_fbm_norm[SB_NOISE_MAX_OCTAVES + 1] = float[](0.0, 1.0, 0.666666686534881591796875,
    0.571428596973419189453125, 0.533333361148834228515625, 0.516129016876220703125, 0.507936537265777587890625,
    0.5039370059967041015625, 0.501960813999176025390625);

/* Perlin fBm in [0, 1]: octaves of rising period (x2) and falling weight (x0.5). */
float noise_perlin_fbm(vec3 p, int period, int octaves, uint seed)
{
    precise float sum = 0.0, weight = 1.0;
    for (int k = 0; k < octaves; k++) {
        sum += weight * noise_perlin(p, period << k, seed + uint(k));
        weight *= 0.5;
    }
    precise float v = 0.5 + 0.5 * sum * noise_fbm_norm[octaves];
    return clamp(v, 0.0, 1.0);
}

/* Worley's cellular noise, 1 - F1 (the distance to the nearest feature
 * point, one per cell, in cell units), clamped to [0, 1]. */
float noise_worley(vec3 p, int cells, uint seed)
{
    precise vec3 x = p * float(cells);
    vec3 cf = floor(x);
    ivec3 c = ivec3(cf);
    precise vec3 f = x - cf; /* within the cell: the same bits one period on */
    precise float best = 8.0;
    for (int oz = -1; oz <= 1; oz++)
        for (int oy = -1; oy <= 1; oy++)
            for (int ox = -1; ox <= 1; ox++) {
                ivec3 o = ivec3(ox, oy, oz);
                precise vec3 d = f - vec3(o) - noise_unit(noise_lattice(c + o, cells, seed));
                precise float d2 = d.x * d.x + d.y * d.y + d.z * d.z;
                best = min(best, d2);
            }
    precise float v = 1.0 - noise_sqrt(min(best, 1.0));
    return v;
}

/* Worley fBm: three octaves of doubling cell count, weights 0.625, 0.25, 0.125. */
float noise_worley_fbm(vec3 p, int cells, uint seed)
{
    precise float v = noise_worley(p, cells, seed) * 0.625 + noise_worley(p, cells * 2, seed + 1u) * 0.25 +
                      noise_worley(p, cells * 4, seed + 2u) * 0.125;
    return v;
}

#endif
