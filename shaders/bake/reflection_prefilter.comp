#version 450
// GGX prefiltering of a cube (config.h, sb_prefilter_push): one level of
// the prefiltered chain from the source's box-filtered chain, as
// prefilter.glsl says.
#extension GL_GOOGLE_include_directive : require
#include "config.h"

layout(local_size_x = SB_PREFILTER_THREADS) in;
layout(std430, binding = SB_PREFILTER_BINDING_SOURCE) readonly buffer Source { vec4 source[]; };
layout(std430, binding = SB_PREFILTER_BINDING_OUT) writeonly buffer Out { vec4 result[]; };
layout(push_constant) uniform Push { sb_prefilter_push pc; };

#include "cube.glsl"

// Bilinear within the face (texel centres; clamped at its edges) at one
// source level.
vec3 prefilter_fetch(vec3 d, uint level)
{
    uint n = max(pc.face_size >> level, 1u);
    vec3 rgb;
    CUBE_BILINEAR(source, pc.source_offsets[level / 4u][level % 4u], n, d, rgb);
    return rgb;
}

#define PREFILTER_THREADS SB_PREFILTER_THREADS
#include "prefilter.glsl"

void main()
{
    prefilter_level p = prefilter_level(pc.face_size, pc.levels, pc.level, pc.samples, pc.roughness, pc.lod_bias,
                                        pc.max_lod, pc.threads_per_texel, pc.groups_x);
    uint texel;
    vec3 rgb;
    if (prefilter_run(p, texel, rgb))
        result[pc.out_offset + texel] = vec4(rgb, 0.0);
}
