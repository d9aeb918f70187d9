#version 450
/* Exposure, bloom, tone mapping and the sRGB encoding, into 8 bits.
 * - AgX (Sobotka), as Blender ships it: the inset to the AgX primaries, a
 *   log2 encoding over [-12.47, +4.03] EV around mid grey, the base contrast
 *   curve (its 6th-order polynomial fit), the outset, then the 2.2 display
 *   power back to linear.
 * - ACES: Hill's fit of the RRT + sRGB ODT (input matrix, rational curve,
 *   output matrix).
 * - GT (Uchimura 2017): toe, linear section, shoulder; defaults P = 1, a = 1,
 *   m = 0.22, l = 0.4, c = 1.33, b = 0.
 * Built once a curve (SB_TONEMAP_OP, AgX by default; passes/tonemap.c
 * dispatches the renderer's): llvmpipe runs the code of every arm of a
 * choice made at run time (the pass 5.0 -> 3.8 ms at 640 x 360). */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#ifndef SB_TONEMAP_OP
#define SB_TONEMAP_OP SB_TONEMAP_AGX
#endif

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
#include "frame.glsl"
layout(std430, set = 0, binding = SB_VIEW_BINDING_EXPOSURE) readonly buffer ExposureBuffer {
    uint bins[SB_HISTOGRAM_BINS];
    sb_exposure_gpu exposure;
};
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform readonly image2D hdr;
layout(set = 0, binding = SB_VIEW_BINDING_BLOOM) uniform sampler2D bloom;
layout(set = 0, binding = SB_VIEW_BINDING_LDR, rgba8) uniform writeonly image2D ldr;

vec3 agx(vec3 c)
{
    const mat3 inset = mat3(0.842479062253094, 0.0423282422610123, 0.0423756549057051,
                            0.0784335999999992, 0.878468636469772, 0.0784336,
                            0.0792237451477643, 0.0791661274605434, 0.879142973793104);
    const mat3 outset = mat3(1.19687900512017, -0.0528968517574562, -0.0529716355144438,
                             -0.0980208811401368, 1.15190312990417, -0.0980434501171241,
                             -0.0990297440797205, -0.0989611768448433, 1.15107367264116);
    const float min_ev = -12.47393, max_ev = 4.026069;
    vec3 x = inset * max(c, vec3(0.0));
    x = clamp((log2(max(x, vec3(1e-10))) - min_ev) / (max_ev - min_ev), 0.0, 1.0);
    vec3 x2 = x * x, x4 = x2 * x2;
    x = 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x - 0.00232;
    x = outset * x;
    return pow(clamp(x, 0.0, 1.0), vec3(2.2));
}

vec3 aces(vec3 c)
{
    /* GLSL matrices are column-major: these are the transposes of Hill's rows. */
    const mat3 input_mat = mat3(0.59719, 0.07600, 0.02840, 0.35458, 0.90834, 0.13383, 0.04823, 0.01566, 0.83777);
    const mat3 output_mat = mat3(1.60475, -0.10208, -0.00327, -0.53108, 1.10813, -0.07276, -0.07367, -0.00605, 1.07602);
    vec3 v = input_mat * c;
    v = (v * (v + 0.0245786) - 0.000090537) / (v * (0.983729 * v + 0.4329510) + 0.238081);
    return clamp(output_mat * v, 0.0, 1.0);
}

vec3 gt(vec3 x)
{
    const float P = 1.0, a = 1.0, m = 0.22, l = 0.4, c = 1.33, b = 0.0;
    float l0 = ((P - m) * l) / a;
    float S0 = m + l0, S1 = m + a * l0;
    float C2 = (a * P) / (P - S1), CP = -C2 / P;
    vec3 w0 = 1.0 - smoothstep(0.0, m, x);
    vec3 w2 = step(m + l0, x);
    vec3 w1 = 1.0 - w0 - w2;
    vec3 T = m * pow(max(x, vec3(0.0)) / m, vec3(c)) + b;
    vec3 S = P - (P - S1) * exp(CP * (x - S0));
    vec3 L = m + a * (x - m);
    return clamp(T * w0 + L * w1 + S * w2, 0.0, 1.0);
}

vec3 srgb_encode(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec3 c = imageLoad(hdr, pixel).rgb * (exposure.state.y / frame.aerial.y);
    if (frame.size.z > 0u) {
        vec2 uv = (vec2(pixel) + 0.5) / vec2(frame.size.xy);
        c += textureLod(bloom, uv, 0.0).rgb * (frame.post.y / float(frame.size.z));
    }
    c = SB_TONEMAP_OP == SB_TONEMAP_ACES ? aces(c) : (SB_TONEMAP_OP == SB_TONEMAP_GT ? gt(c) : agx(c));
    imageStore(ldr, pixel, vec4(srgb_encode(c), 1.0));
}
