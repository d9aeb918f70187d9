// The real spherical-harmonic basis of order 2 (9 functions, Sloan 2008's
// order and constants) of a unit direction in world axes; baker/sh.c is
// its C twin.
#ifndef SB_SH_GLSL
#define SB_SH_GLSL

#include "config.h"

void sh9_basis(vec3 d, out float y[SB_PROBE_SH])
{
    y[0] = 0.28209479177387814;
    y[1] = 0.4886025119029199 * d.y;
    y[2] = 0.4886025119029199 * d.z;
    y[3] = 0.4886025119029199 * d.x;
    y[4] = 1.0925484305920792 * d.x * d.y;
    y[5] = 1.0925484305920792 * d.y * d.z;
    y[6] = 0.31539156525252005 * (3.0 * d.z * d.z - 1.0);
    y[7] = 1.0925484305920792 * d.x * d.z;
    y[8] = 0.5462742152960396 * (d.x * d.x - d.y * d.y);
}

// Ray i of n: the spherical Fibonacci set, y up, the azimuth from an
// integer golden-ratio sequence (exact in 32 bits at any n).
vec3 probe_direction(uint i, uint n)
{
    float y = 1.0 - (2.0 * float(i) + 1.0) / float(n);
    float phi = 6.283185307179586 * (float(i * 0x9E3779B9u) * 2.3283064365386963e-10);
    float r = sqrt(max(0.0, 1.0 - y * y));
    return vec3(r * cos(phi), y, r * sin(phi));
}

// The sun table's directions (config.h, SB_SUN_SIDE; physics/sh.h,
// sb_sun_table_direction): the corners (j % side, j / side) of a grid over
// the upper hemisphere's octahedral map (y up), turned by 45 degrees so
// that the map fills the square: u = x + z and v = x - z over |x| + |y| +
// |z|, each from -1 to 1.
// A direction about the sun table's direction j drawn with the density of
// its bilinear weight over the map (a tent a grid step wide each way,
// folded back at the horizon), from 4 uniform numbers hashed from `seed`
// (sun_table_sample's C twin draws the same): a ray toward it estimates
// the table's value at j as the mean of its neighbourhood, the mean that
// bilinear reading between the directions needs.
uint sun_hash(uint x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

vec3 sun_table_sample(uint j, uint seed)
{
    uint h0 = sun_hash(seed), h1 = sun_hash(h0), h2 = sun_hash(h1), h3 = sun_hash(h2);
    const float unit = 5.9604644775390625e-08; // 2^-24
    float step = 2.0 / float(SB_SUN_SIDE - 1);
    float u = -1.0 + step * float(j % uint(SB_SUN_SIDE)) + step * (float(h0 >> 8) - float(h1 >> 8)) * unit;
    float v = -1.0 + step * float(j / uint(SB_SUN_SIDE)) + step * (float(h2 >> 8) - float(h3 >> 8)) * unit;
    u = u > 1.0 ? 2.0 - u : (u < -1.0 ? -2.0 - u : u);
    v = v > 1.0 ? 2.0 - v : (v < -1.0 ? -2.0 - v : v);
    float x = 0.5 * (u + v), z = 0.5 * (u - v);
    return normalize(vec3(x, max(1.0 - abs(x) - abs(z), 0.0), z));
}

// The 4 table directions around the sun s and their bilinear weights (a
// sun below the horizon is read at the horizon under it).
void sun_table_weights(vec3 s, out uint at[4], out float w[4])
{
    vec3 d = vec3(s.x, max(s.y, 0.0), s.z);
    float a = abs(d.x) + d.y + abs(d.z);
    d = a > 0.0 ? d / a : vec3(0.0, 1.0, 0.0);
    float side = float(SB_SUN_SIDE - 1);
    vec2 t = clamp((vec2(d.x + d.z, d.x - d.z) + 1.0) * (0.5 * side), vec2(0.0), vec2(side));
    vec2 base = min(floor(t), vec2(side - 1.0));
    vec2 f = t - base;
    uint i = uint(base.x) + uint(base.y) * uint(SB_SUN_SIDE);
    at[0] = i;
    at[1] = i + 1u;
    at[2] = i + uint(SB_SUN_SIDE);
    at[3] = i + uint(SB_SUN_SIDE) + 1u;
    w[0] = (1.0 - f.x) * (1.0 - f.y);
    w[1] = f.x * (1.0 - f.y);
    w[2] = (1.0 - f.x) * f.y;
    w[3] = f.x * f.y;
}

#endif
