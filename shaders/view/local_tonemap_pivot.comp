#version 450
/* Local tone mapping, step 2: one invocation a cell column of the grid. A
 * column with pixels adds its mean (the integer quotient of its bins' sums
 * by their counts) to the frame's pivot sum and counts itself: the pivot is
 * the mean of the columns' means. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "local_tonemap.glsl"

layout(local_size_x = 64) in;

void main()
{
    uint column = gl_GlobalInvocationID.x, columns = ltm.grid.x * ltm.grid.y;
    if (column >= columns)
        return;
    uint sum = 0u, count = 0u;
    for (uint b = 0u; b < SB_LTM_BINS; b++) {
        uvec2 cell = ltm_cells[b * columns + column];
        sum += cell.x;
        count += cell.y;
    }
    if (count > 0u) {
        atomicAdd(ltm.pivot.x, sum / count);
        atomicAdd(ltm.pivot.y, 1u);
    }
}
