/* A .cube 3D LUT (formats/lut3d.h) as skyview's grading passes read it:
 * its domain, size and entries in SB_VIEW_BINDING_GRADE_LUT, looked up
 * with trilinear interpolation. */
#ifndef SB_LUT3D_GLSL
#define SB_LUT3D_GLSL

#include "grading_gpu.h"
#include "view_gpu.h"

layout(std430, set = 0, binding = SB_VIEW_BINDING_GRADE_LUT) readonly buffer GradeLut {
    vec4 lut_min; /* rgb: the domain's minimum; w: the LUT's size N */
    vec4 lut_max; /* rgb: the domain's maximum */
    float lut_rgb[]; /* N^3 RGB triples, red fastest */
};

vec3 lut_entry(ivec3 i, int n)
{
    int k = ((i.z * n + i.y) * n + i.x) * 3;
    return vec3(lut_rgb[k], lut_rgb[k + 1], lut_rgb[k + 2]);
}

/* The LUT at v: v scaled from the domain to the nodes (clamped to them),
 * then trilinear. */
vec3 lut_apply(vec3 v)
{
    int n = int(lut_min.w);
    vec3 x = clamp((v - lut_min.rgb) / (lut_max.rgb - lut_min.rgb), 0.0, 1.0) * float(n - 1);
    ivec3 i0 = min(ivec3(x), ivec3(n - 2));
    vec3 f = x - vec3(i0);
    vec3 c00 = mix(lut_entry(i0, n), lut_entry(i0 + ivec3(1, 0, 0), n), f.x);
    vec3 c10 = mix(lut_entry(i0 + ivec3(0, 1, 0), n), lut_entry(i0 + ivec3(1, 1, 0), n), f.x);
    vec3 c01 = mix(lut_entry(i0 + ivec3(0, 0, 1), n), lut_entry(i0 + ivec3(1, 0, 1), n), f.x);
    vec3 c11 = mix(lut_entry(i0 + ivec3(0, 1, 1), n), lut_entry(i0 + ivec3(1, 1, 1), n), f.x);
    return mix(mix(c00, c10, f.y), mix(c01, c11, f.y), f.z);
}

#endif
