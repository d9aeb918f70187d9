#version 450
/* Colour grading through a 3D LUT (a .cube file, formats/lut3d.h) on the
 * display-referred frame: the tone-mapped, sRGB-encoded 8-bit pixels, as
 * DaVinci Resolve applies a .cube to an sRGB clip. Each pixel's code q
 * goes in as q / 255 (scaled from the LUT's domain to its nodes), comes
 * out by trilinear interpolation and is rounded to the nearest code, so a
 * neutral LUT returns every code unchanged. */
#extension GL_GOOGLE_include_directive : require
#include "config.h"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(std430, set = 0, binding = SB_VIEW_BINDING_FRAME) readonly buffer FrameBuffer {
    sb_frame_gpu frame;
};
layout(std430, set = 0, binding = SB_VIEW_BINDING_GRADE_LUT) readonly buffer GradeLut {
    vec4 lut_min; /* rgb: the domain's minimum; w: the LUT's size N */
    vec4 lut_max; /* rgb: the domain's maximum */
    float lut_rgb[]; /* N^3 RGB triples, red fastest */
};
layout(set = 0, binding = SB_VIEW_BINDING_LDR, rgba8) uniform image2D ldr;

vec3 lut_entry(ivec3 i, int n)
{
    int k = ((i.z * n + i.y) * n + i.x) * 3;
    return vec3(lut_rgb[k], lut_rgb[k + 1], lut_rgb[k + 2]);
}

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec4 v = imageLoad(ldr, pixel);
    int n = int(lut_min.w);
    vec3 x = clamp((v.rgb - lut_min.rgb) / (lut_max.rgb - lut_min.rgb), 0.0, 1.0) * float(n - 1);
    ivec3 i0 = min(ivec3(x), ivec3(n - 2));
    vec3 f = x - vec3(i0);
    vec3 c00 = mix(lut_entry(i0, n), lut_entry(i0 + ivec3(1, 0, 0), n), f.x);
    vec3 c10 = mix(lut_entry(i0 + ivec3(0, 1, 0), n), lut_entry(i0 + ivec3(1, 1, 0), n), f.x);
    vec3 c01 = mix(lut_entry(i0 + ivec3(0, 0, 1), n), lut_entry(i0 + ivec3(1, 0, 1), n), f.x);
    vec3 c11 = mix(lut_entry(i0 + ivec3(0, 1, 1), n), lut_entry(i0 + ivec3(1, 1, 1), n), f.x);
    vec3 g = mix(mix(c00, c10, f.y), mix(c01, c11, f.y), f.z);
    imageStore(ldr, pixel, vec4(floor(clamp(g, 0.0, 1.0) * 255.0 + 0.5) / 255.0, v.a));
}
