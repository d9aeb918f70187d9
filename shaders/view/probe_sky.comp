#version 450
/* The sky's radiance as order-2 SH, for relighting the probes: the
 * sky-view LUT (a layer a light in the sky; the planet's lit ground below
 * the horizon included, the sun's and the moon's disks not: a
 * disk's light is the key light's direct light) over SB_PROBE_SKY_DIRECTIONS
 * spherical Fibonacci directions, or the same integral per direction from
 * the top of the atmosphere for a camera above it. One workgroup; the
 * partial sums are added in a fixed tree order. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"
#define PROBE_LIGHT_WRITABLE
#include "probes.glsl"

layout(local_size_x = SB_PROBE_SKY_THREADS) in;
layout(set = 0, binding = SB_VIEW_BINDING_SKY_VIEW) uniform sampler2DArray sky_view;

shared vec3 partial[SB_PROBE_SKY_THREADS][SB_PROBE_SH];

vec3 radiance(vec3 d)
{
    vec3 up = normalize(frame.camera_km.xyz);
    bool inside = frame.camera_km.w < atmosphere_thickness();
    vec3 L = vec3(0.0);
    for (int i = 0; i < sky_light_count(); i++) {
        vec3 l = light_direction(i);
        if (inside) {
            L += textureLod(sky_view, vec3(sky_view_uv_toward(d, l), float(i)), 0.0).rgb / frame.aerial.y;
        } else { /* the world is on the ground: its sky seen from there */
            float mu = clamp(dot(up, d), -1.0, 1.0), mu_s = clamp(dot(up, l), -1.0, 1.0);
            L += sky_radiance(0.0, mu, mu_s, clamp(dot(d, l), -1.0, 1.0)) * light_color(i);
        }
    }
    return L;
}

void main()
{
    uint t = gl_LocalInvocationID.x;
    vec3 sum[SB_PROBE_SH];
    for (int k = 0; k < SB_PROBE_SH; k++)
        sum[k] = vec3(0.0);
    const float w = 4.0 * PI / float(SB_PROBE_SKY_DIRECTIONS);
    for (uint i = t; i < SB_PROBE_SKY_DIRECTIONS; i += SB_PROBE_SKY_THREADS) {
        vec3 d = probe_direction(i, SB_PROBE_SKY_DIRECTIONS);
        vec3 L = radiance(d) * w;
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
