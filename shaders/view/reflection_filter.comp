#version 450
/* Level `pc.level` of relit cube `pc.item`, GGX-prefiltered from its
 * box chain as the bake prefilters (prefilter.glsl), laid out per level by
 * sb_relight_gpu. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#define REFLECTION_CUBES_WRITABLE
#include "reflections.glsl"

layout(local_size_x = SB_PREFILTER_THREADS) in;
layout(push_constant) uniform ViewPush { sb_view_push pc; };
layout(std430, set = 0, binding = SB_VIEW_BINDING_REFLECTION_CHAIN) readonly buffer Chain { vec4 chain[]; };
layout(std430, set = 0, binding = SB_VIEW_BINDING_RELIGHT) readonly buffer Relight { sb_relight_gpu relight; };

vec3 prefilter_fetch(vec3 d, uint level)
{
    uint n = max(reflections.info.x >> level, 1u);
    vec3 rgb;
    CUBE_BILINEAR(chain, reflection_level_offset(level), n, d, rgb);
    return rgb;
}

#define PREFILTER_THREADS SB_PREFILTER_THREADS
#include "prefilter.glsl"

void main()
{
    uint l = pc.level, levels = reflections.info.y;
    uvec4 at = relight.level[l];
    prefilter_level p = prefilter_level(reflections.info.x, levels, l, at.x, uintBitsToFloat(at.w), 0.0,
                                        levels > 3u ? float(levels - 3u) : 0.0, at.y, at.z);
    uint texel;
    vec3 rgb;
    if (prefilter_run(p, texel, rgb))
        cube_texels[pc.item * reflections.level_offsets[3].w + reflection_level_offset(l) + texel] = vec4(rgb, 0.0);
}
