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

#endif
