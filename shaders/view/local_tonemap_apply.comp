#version 450
/* Local tone mapping, step 4: each pixel's base layer, the grid read at
 * its position and log2 luminance (trilinear: deviation over count), is
 * its neighbourhood's log2 luminance among pixels of a like luminance,
 * relative to the frame's pivot. Its distance from the pivot is scaled by
 * the contrast, the detail (the pixel less its base) kept: the pixel is
 * multiplied by 2^((contrast - 1) base). A frame of one luminance has a
 * base of exactly 0 and is left as it was. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "local_tonemap.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
#include "frame.glsl"
layout(std430, set = 0, binding = SB_VIEW_BINDING_EXPOSURE) readonly buffer ExposureBuffer {
    uint bins[SB_HISTOGRAM_BINS];
    sb_exposure_gpu exposure;
};
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform image2D hdr;

vec2 blurred(uvec3 c)
{
    return uintBitsToFloat(ltm_cells[ltm.grid.x * ltm.grid.y * ltm.grid.z + ltm_cell(c)]);
}

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec4 h = imageLoad(hdr, pixel);
    float lum = dot(h.rgb * (exposure.state.y / frame.aerial.y), vec3(SB_LUMINANCE_RGB));
    if (!(lum > 0.0))
        return;
    float l = ltm_log_luminance(lum);
    vec3 g = vec3((vec2(pixel) + 0.5) / float(ltm.grid.w) - 0.5, (l - SB_LTM_MIN_EV) / LTM_BIN_EV - 0.5);
    g = clamp(g, vec3(0.0), vec3(ltm.grid.xyz - 1u));
    uvec3 c0 = uvec3(g);
    uvec3 c1 = min(c0 + 1u, ltm.grid.xyz - 1u);
    vec3 f = g - vec3(c0);
    vec2 s = vec2(0.0);
    for (uint k = 0u; k < 8u; k++) {
        uvec3 pick = uvec3(k & 1u, (k >> 1) & 1u, k >> 2);
        vec3 w3 = mix(1.0 - f, f, vec3(pick));
        s += w3.x * w3.y * w3.z * blurred(mix(c0, c1, bvec3(pick)));
    }
    if (!(s.y > 0.0))
        return;
    float base = s.x / (s.y * float(SB_LTM_Q)); /* EV from the pivot */
    imageStore(hdr, pixel, vec4(h.rgb * exp2((ltm.params.x - 1.0) * base), h.a));
}
