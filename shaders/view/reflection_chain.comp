#version 450
/* Level `pc.level` of a relit cube's box-filtered chain (the means of 2
 * x 2 texels of the level above, as the bake's sb_cube_build_mips), which
 * reflection_filter.comp reads. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "reflections_gpu.h"

layout(local_size_x = SB_RELIGHT_THREADS) in;
layout(push_constant) uniform ViewPush { sb_view_push pc; };
layout(std430, set = 0, binding = SB_VIEW_BINDING_REFLECTIONS) readonly buffer ReflectionBuffer {
    sb_reflections_gpu reflections;
};
layout(std430, set = 0, binding = SB_VIEW_BINDING_REFLECTION_CHAIN) buffer Chain { vec4 chain[]; };

void main()
{
    uint l = pc.level, m = max(reflections.info.x >> l, 1u), texel = gl_GlobalInvocationID.x;
    if (texel >= 6u * m * m)
        return;
    uint face = texel / (m * m), in_face = texel - face * m * m, x = in_face % m, y = in_face / m, w = 2u * m;
    uint above = reflections.level_offsets[(l - 1u) / 4u][(l - 1u) % 4u] + face * w * w + 2u * y * w + 2u * x;
    vec4 sum = chain[above] + chain[above + 1u] + chain[above + w] + chain[above + w + 1u];
    chain[reflections.level_offsets[l / 4u][l % 4u] + texel] = 0.25 * sum;
}
