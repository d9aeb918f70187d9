#version 450
/* The sky's radiance as order-2 SH, for relighting the probes and the
 * reflection cubes: sky_light.glsl's over SB_PROBE_SKY_DIRECTIONS
 * spherical Fibonacci directions. One workgroup; the partial sums are
 * added in a fixed tree order. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"
#define PROBE_LIGHT_WRITABLE
#include "probes.glsl"
#include "sky_light.glsl"

layout(local_size_x = SB_PROBE_SKY_THREADS) in;
shared vec3 partial[SB_PROBE_SKY_THREADS][SB_PROBE_SH];

void main()
{
    uint t = gl_LocalInvocationID.x;
    vec3 sum[SB_PROBE_SH];
    for (int k = 0; k < SB_PROBE_SH; k++)
        sum[k] = vec3(0.0);
    const float w = 4.0 * PI / float(SB_PROBE_SKY_DIRECTIONS);
    for (uint i = t; i < SB_PROBE_SKY_DIRECTIONS; i += SB_PROBE_SKY_THREADS) {
        vec3 d = probe_direction(i, SB_PROBE_SKY_DIRECTIONS);
        vec3 L = sky_light_radiance(d) * w;
        float y[SB_PROBE_SH];
        sh9_basis(d, y);
        for (int k = 0; k < SB_PROBE_SH; k++)
            sum[k] += L * y[k];
    }
    for (int k = 0; k < SB_PROBE_SH; k++)
        partial[t][k] = sum[k];
    barrier();
    for (uint stride = SB_PROBE_SKY_THREADS / 2; stride > 0; stride /= 2) {
        if (t < stride)
            for (int k = 0; k < SB_PROBE_SH; k++)
                partial[t][k] += partial[t + stride][k];
        barrier();
    }
    if (t < SB_PROBE_SH)
        sky_sh[t] = vec4(fp16_safe(partial[0][t]), 0.0);
}
