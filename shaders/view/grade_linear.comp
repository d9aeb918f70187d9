#version 450
/* Scene-linear grading (runtime/grading.c, passes/grade_linear.c), in place on the lit frame after
 * exposure is metered and before bloom and the tone curve, on the exposed
 * values (mid grey at 0.18):
 * - the colour matrix: white balance (a von Kries adaptation in Bradford's
 *   cone space from the chosen illuminant to D65), then saturation about
 *   the Rec.709 luminance;
 * - contrast: each channel pivot * (c / pivot)^contrast, negatives to 0;
 * - with SB_GRADE_LOG_LUT, a .cube LUT in ACEScct (AP1 primaries, the
 *   ACEScct curve of S-2016-001), as grading applications apply a look
 *   made in that space.
 * The frame is stored as before: radiance, divided by the exposure again. */
#extension GL_GOOGLE_include_directive : require
#include "grading_gpu.h"
#include "view_gpu.h"
#ifdef SB_GRADE_LOG_LUT
#include "lut3d.glsl"
#endif

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
#include "frame.glsl"
layout(std430, set = 0, binding = SB_VIEW_BINDING_EXPOSURE) readonly buffer ExposureBuffer {
    uint bins[SB_HISTOGRAM_BINS];
    sb_exposure_gpu exposure;
};
layout(std430, set = 0, binding = SB_VIEW_BINDING_GRADING) readonly buffer GradingBuffer {
    sb_grading_gpu grading;
};
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform image2D hdr;

vec3 rows(vec4 m[3], vec3 c)
{
    return vec3(dot(m[0].xyz, c), dot(m[1].xyz, c), dot(m[2].xyz, c));
}

#ifdef SB_GRADE_LOG_LUT
/* ACEScct (S-2016-001): linear below 2^-7, log2 above. */
vec3 acescct_encode(vec3 x)
{
    return mix(10.5402377416545 * x + 0.0729055341958355, (log2(max(x, vec3(0.0078125))) + 9.72) / 17.52,
               greaterThan(x, vec3(0.0078125)));
}

vec3 acescct_decode(vec3 y)
{
    /* beyond 65504, the half-float maximum, is clamped */
    vec3 lg = exp2(min(y, vec3(1.468)) * 17.52 - 9.72);
    return mix((y - 0.0729055341958355) / 10.5402377416545, lg, greaterThan(y, vec3(0.155251141552511)));
}
#endif

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec4 h = imageLoad(hdr, pixel);
    float to_exposed = exposure.state.y / frame.aerial.y;
    vec3 c = rows(grading.matrix, h.rgb * to_exposed);
    float contrast = grading.tone.x, pivot = grading.tone.y;
    if (contrast != 1.0)
        c = pivot * pow(max(c, vec3(0.0)) / pivot, vec3(contrast));
#ifdef SB_GRADE_LOG_LUT
    c = rows(grading.from_ap1, acescct_decode(lut_apply(acescct_encode(rows(grading.to_ap1, c)))));
#endif
    c /= to_exposed;
    /* finite, within a half */
    c = clamp(mix(c, vec3(0.0), isnan(c)), vec3(-65504.0), vec3(65504.0));
    imageStore(hdr, pixel, vec4(c, h.a));
}
