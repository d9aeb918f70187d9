#version 450
// One mip level of every texture (baker/surfaces.h, config.h's
// sb_texture_mips_push): texel (x, y) of level `level` of texture z is the
// mean of the 2 x 2 texels above it (the edge texel again where the level
// above is odd or 1 wide), averaged in linear light for an sRGB texture
// and encoded back, rounded to 8 bits.
#extension GL_GOOGLE_include_directive : require
#include "config.h"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(std430, binding = SB_TEXTURE_MIPS_BINDING_TEXTURES) readonly buffer Textures { uvec4 textures[]; };
layout(std430, binding = SB_TEXTURE_MIPS_BINDING_TEXELS) buffer Texels { uint texels[]; };
layout(push_constant) uniform Push { sb_texture_mips_push pc; };

float to_linear(float c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

float to_srgb(float c)
{
    return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

void main()
{
    uvec4 t = textures[gl_GlobalInvocationID.z];
    if (pc.level >= (t.z & 0xffu))
        return;
    bool srgb = ((t.z >> 12) & 1u) != 0u;
    uint w = t.y & 0xffffu, h = t.y >> 16, above = t.x;
    for (uint l = 1u; l < pc.level; l++) {
        above += w * h;
        w = max(w >> 1, 1u);
        h = max(h >> 1, 1u);
    }
    uint at = above + w * h, dw = max(w >> 1, 1u), dh = max(h >> 1, 1u);
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= dw || p.y >= dh)
        return;
    vec4 sum = vec4(0.0);
    for (uint j = 0u; j < 2u; j++)
        for (uint i = 0u; i < 2u; i++) {
            uint x = min(2u * p.x + i, w - 1u), y = min(2u * p.y + j, h - 1u);
            vec4 c = unpackUnorm4x8(texels[above + y * w + x]);
            if (srgb)
                c.rgb = vec3(to_linear(c.r), to_linear(c.g), to_linear(c.b));
            sum += c;
        }
    vec4 mean = 0.25 * sum;
    if (srgb)
        mean.rgb = vec3(to_srgb(mean.r), to_srgb(mean.g), to_srgb(mean.b));
    texels[at + p.y * dw + p.x] = packUnorm4x8(mean);
}
