#version 450
/*
 * Each probe's irradiance as order-2 SH, for this frame's sun and sky
 * (docs/probes.md, "Runtime"):
 * - the sky it sees: the SH of the product of its visibility V and the
 *   sky's radiance L, by the triple-product tensor (truncated to order 2);
 * - the bounce, baked (sky_bounce): sum_k B[m][k] L_k in order 1, and
 *   the sun's from its table (sun_bounce) E_sun sum_j w_j(sun) T_j S[m],
 *   or without it sum_k B[m][k] E_sun Y_k(sun);
 * - or, without it, modelled: the directions its rays hit (the SH of 1 - V) carry the
 *   radiance of surfaces of the world's mean albedo rho lit as the probe is
 *   on average, E = pi (mean of V L) + E_sun v_sun / 4 (v_sun: V at the sun),
 *   bounced without end: L_b = rho E / (pi (1 - rho f)), f the hit fraction;
 * - convolved with the clamped cosine.
 * A probe that sees no sky gets nothing, however bright the sky.
 */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"
#define PROBE_LIGHT_WRITABLE
#include "probes.glsl"

layout(local_size_x = SB_PROBE_THREADS) in;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= probes.grid.w)
        return;
    float v[SB_PROBE_SH];
    uint record = probe_record(i);
    for (int k = 0; k < 4; k++) {
        v[k] = probe_data[record + 1][k];
        v[4 + k] = probe_data[record + 2][k];
    }
    v[8] = probe_data[record + 3].x;

    vec3 vl[SB_PROBE_SH];
    for (int k = 0; k < SB_PROBE_SH; k++)
        vl[k] = vec3(0.0);
    uint entries = uint(probes.origin_m.w);
    for (uint e = 0; e < entries; e++) {
        vec4 t = probes.tensor[e];
        vl[int(t.w)] += t.x * v[int(t.y)] * sky_sh[int(t.z)].rgb;
    }

    /* the sun at the probe, and its mean irradiance over all orientations */
    vec3 up = normalize(frame.camera_km.xyz);
    vec3 l = key_direction();
    float ys[SB_PROBE_SH];
    sh9_basis(l, ys);
    float v_sun = 0.0;
    for (int k = 0; k < SB_PROBE_SH; k++)
        v_sun += v[k] * ys[k];
    v_sun = clamp(v_sun, 0.0, 1.0);
    vec3 e_sun = atm.solar_irradiance.rgb * key_color() * sun_transmittance_rgb(0.0, dot(up, l));
    const float Y0 = 0.28209479177387814;
    vec3 e_mean = PI * vl[0] * Y0 + e_sun * (0.25 * v_sun);
    float hit = clamp(1.0 - v[0] * Y0, 0.0, 1.0); /* the hit fraction: 1 - V's mean */
    vec3 rho = probes.bounce_albedo.rgb;
    vec3 l_bounce = rho * e_mean / (PI * max(1.0 - rho * hit, vec3(1e-3)));
    bool baked = probes.spacing_m.w != 0.0, sun_table = probes.spacing_m.w == 2.0;
    vec3 bounce[SB_BOUNCE_SH];
    for (int m = 0; m < SB_BOUNCE_SH; m++) {
        bounce[m] = vec3(0.0);
        for (int k = 0; k < SB_PROBE_SH && baked; k++) {
            uint at = 3u * uint(m * SB_PROBE_SH + k);
            vec3 b;
            for (int c = 0; c < 3; c++) /* 3 floats of the packed rgb triples */
                b[c] = probe_data[record + SB_PROBE_BOUNCE_VEC4 + (at + uint(c)) / 4u][(at + uint(c)) % 4u];
            bounce[m] += b * (sky_sh[k].rgb + (sun_table ? vec3(0.0) : e_sun * ys[k]));
        }
    }
    if (sun_table) { /* the sun's bounce from its table, bilinear between its directions */
        uint at[4];
        float w[4], t = 0.0;
        sun_table_weights(l, at, w);
        uint base = record + SB_PROBE_SUN_VEC4;
        for (int q = 0; q < 4; q++)
            t += w[q] * probe_data[base + at[q] / 4u][at[q] % 4u];
        for (int m = 0; m < SB_BOUNCE_SH; m++)
            for (int c = 0; c < 3; c++) {
                uint s = uint(SB_SUN_DIRECTIONS + 3 * m + c);
                bounce[m][c] += e_sun[c] * t * probe_data[base + s / 4u][s % 4u];
            }
    }

    for (int k = 0; k < SB_PROBE_SH; k++) {
        float occluded = (k == 0 ? 1.0 / Y0 : 0.0) - v[k]; /* the SH of 1 - V */
        vec3 radiance = vl[k] + (baked ? (k < SB_BOUNCE_SH ? bounce[k] : vec3(0.0)) : l_bounce * occluded);
        probe_irradiance[SB_PROBE_SH * i + k] = vec4(fp16_safe(SH_COSINE[SH_BAND[k]] * radiance), 0.0);
    }
}
