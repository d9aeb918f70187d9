#version 450
/* Local tone mapping, step 3: one invocation a cell. The cell's sum less
 * its count times the pivot (an exact integer: 0 in a frame of one
 * luminance), then both blurred by [1 2 1] along each of the grid's three
 * axes, as floats. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "local_tonemap.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

void main()
{
    uvec3 c = gl_GlobalInvocationID;
    if (any(greaterThanEqual(c, ltm.grid.xyz)))
        return;
    uint pivot = ltm.pivot.y > 0u ? ltm.pivot.x / ltm.pivot.y : 0u;
    vec2 sum = vec2(0.0);
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                ivec3 n = ivec3(c) + ivec3(dx, dy, dz);
                if (any(lessThan(n, ivec3(0))) || any(greaterThanEqual(n, ivec3(ltm.grid.xyz))))
                    continue;
                uvec2 cell = ltm_cells[ltm_cell(uvec3(n))];
                int deviation = int(cell.x) - int(cell.y) * int(pivot);
                float w = float((2 - abs(dx)) * (2 - abs(dy)) * (2 - abs(dz)));
                sum += w * vec2(float(deviation), float(cell.y));
            }
    uint n = ltm.grid.x * ltm.grid.y * ltm.grid.z;
    ltm_cells[n + ltm_cell(c)] = floatBitsToUint(sum);
}
