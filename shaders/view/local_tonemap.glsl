/* Local tone mapping's shared declarations (runtime/passes/local_tonemap.c): its
 * constants and bilateral grid. The grid holds, per cell, the fixed-point
 * sum of the biased log2 luminance of the pixels that fall in it and their
 * count (exact integers, so that the result does not depend on the order
 * the pixels are added in), then the cell's sum less the pivot's share,
 * blurred. */
#ifndef SB_LOCAL_TONEMAP_GLSL
#define SB_LOCAL_TONEMAP_GLSL

#include "local_tonemap_gpu.h"
#include "view_gpu.h"

layout(std430, set = 0, binding = SB_VIEW_BINDING_LOCAL_TONEMAP) buffer LocalTonemapBuffer {
    sb_local_tonemap_gpu ltm;
};
layout(std430, set = 0, binding = SB_VIEW_BINDING_LOCAL_TONEMAP_GRID) buffer LocalTonemapGrid {
    uvec2 ltm_cells[]; /* grid.x * grid.y * grid.z (sum, count), x fastest then bins; then as many vec2
                          (the deviation from the pivot, the count), blurred, as floats' bits */
};

const float LTM_BIN_EV = (SB_LTM_MAX_EV - SB_LTM_MIN_EV) / float(SB_LTM_BINS);

uint ltm_cell(uvec3 c)
{
    return (c.z * ltm.grid.y + c.y) * ltm.grid.x + c.x;
}

/* The exposed luminance's log2, clamped to the grid's range. */
float ltm_log_luminance(float y)
{
    return clamp(log2(y), SB_LTM_MIN_EV, SB_LTM_MAX_EV - 1e-3);
}

#endif
