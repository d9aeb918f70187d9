#version 450
/* Local tone mapping, step 1: one invocation a pixel. A pixel with light
 * adds its biased fixed-point log2 luminance (exposed) and a count of one to
 * its cell and bin, by integer atomics on the grid (cleared before), so the
 * sums do not depend on the order the pixels are added in. A workgroup a
 * cell with shared bins was three times slower on lavapipe: its barriers
 * make llvmpipe run the invocations as coroutines, and a cell of 20 pixels
 * square left a 16 x 16 workgroup's second pass mostly idle.
 *
 * With SB_SUBGROUPS (chosen where the device's subgroups can ballot and
 * add, runtime/passes/local_tonemap.c), the invocations of a subgroup that share a
 * cell and bin add their sums first and one of them adds the total: a GPU
 * serialises atomics on one address, and one bin of one cell takes most of
 * a smooth region's pixels (the pass took 0.112 ms on an H100 at 1920 x
 * 1080 without, 0.086 with; 0.061 with a workgroup a cell, which took
 * lavapipe 13 ms against 7.6). */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "local_tonemap.glsl"
#ifdef SB_SUBGROUPS
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#endif

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
#include "frame.glsl"
layout(std430, set = 0, binding = SB_VIEW_BINDING_EXPOSURE) readonly buffer ExposureBuffer {
    uint bins[SB_HISTOGRAM_BINS];
    sb_exposure_gpu exposure;
};
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform readonly image2D hdr;

void main()
{
    uvec2 p = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(p, frame.size.xy)))
        return;
    float to_exposed = exposure.state.y / frame.aerial.y;
    vec3 c = imageLoad(hdr, ivec2(p)).rgb * to_exposed;
    float lum = dot(c, vec3(SB_LUMINANCE_RGB));
    if (!(lum > 0.0))
        return;
    float l = ltm_log_luminance(lum);
    uint bin = min(uint((l - SB_LTM_MIN_EV) / LTM_BIN_EV), uint(SB_LTM_BINS - 1));
    uint cell = ltm_cell(uvec3(p / ltm.grid.w, bin));
    uint value = uint(int(round(l * SB_LTM_Q)) + SB_LTM_BIAS);
#ifdef SB_SUBGROUPS
    /* One cell and bin a turn: the first invocation's, and those that share it. */
    for (;;) {
        if (cell == subgroupBroadcastFirst(cell)) {
            uint sum = subgroupAdd(value), count = subgroupAdd(1u);
            if (subgroupElect()) {
                atomicAdd(ltm_cells[cell].x, sum);
                atomicAdd(ltm_cells[cell].y, count);
            }
            break;
        }
    }
#else
    atomicAdd(ltm_cells[cell].x, value);
    atomicAdd(ltm_cells[cell].y, 1u);
#endif
}
