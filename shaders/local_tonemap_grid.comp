#version 450
/* Local tone mapping, step 1: one workgroup a cell column of the bilateral
 * grid. Each pixel of the cell's square with light adds its biased
 * fixed-point log2 luminance (exposed) to its bin; the cell's mean is added
 * to the frame's pivot sum (the pivot is the mean of the cells' means). */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#include "local_tonemap.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
layout(std430, set = 0, binding = SB_VIEW_BINDING_FRAME) readonly buffer FrameBuffer {
    sb_frame_gpu frame;
};
layout(std430, set = 0, binding = SB_VIEW_BINDING_EXPOSURE) readonly buffer ExposureBuffer {
    uint bins[SB_HISTOGRAM_BINS];
    sb_exposure_gpu exposure;
};
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform readonly image2D hdr;

shared uint bin_sum[SB_LTM_BINS];
shared uint bin_count[SB_LTM_BINS];

void main()
{
    uint i = gl_LocalInvocationIndex;
    if (i < SB_LTM_BINS) {
        bin_sum[i] = 0u;
        bin_count[i] = 0u;
    }
    barrier();
    uint side = ltm.grid.w;
    uvec2 origin = gl_WorkGroupID.xy * side;
    float to_exposed = exposure.state.y / frame.aerial.y;
    for (uint y = gl_LocalInvocationID.y; y < side; y += 16u)
        for (uint x = gl_LocalInvocationID.x; x < side; x += 16u) {
            uvec2 p = origin + uvec2(x, y);
            if (any(greaterThanEqual(p, frame.size.xy)))
                continue;
            vec3 c = imageLoad(hdr, ivec2(p)).rgb * to_exposed;
            float lum = dot(c, vec3(SB_LUMINANCE_RGB));
            if (!(lum > 0.0))
                continue;
            float l = ltm_log_luminance(lum);
            uint bin = min(uint((l - SB_LTM_MIN_EV) / LTM_BIN_EV), uint(SB_LTM_BINS - 1));
            atomicAdd(bin_sum[bin], uint(int(round(l * SB_LTM_Q)) + SB_LTM_BIAS));
            atomicAdd(bin_count[bin], 1u);
        }
    barrier();
    if (i < SB_LTM_BINS)
        ltm_cells[ltm_cell(uvec3(gl_WorkGroupID.xy, i))] = uvec2(bin_sum[i], bin_count[i]);
    if (i == 0u) {
        uint sum = 0u, count = 0u;
        for (uint b = 0u; b < SB_LTM_BINS; b++) {
            sum += bin_sum[b];
            count += bin_count[b];
        }
        if (count > 0u) {
            atomicAdd(ltm.pivot.x, sum / count);
            atomicAdd(ltm.pivot.y, 1u);
        }
    }
}
