#version 450
/* Transmittance to the top of the atmosphere, 256x64 RGB fp32 (Hillaire 2020
 * parameterisation, see atmosphere.glsl). At most 40 density samples a texel. */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#include "atmosphere.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { float result[]; };
layout(push_constant) uniform Push { sb_bake_push pc; };

void main()
{
    uvec2 texel = gl_GlobalInvocationID.xy;
    if (texel.x >= pc.width || texel.y >= pc.height)
        return;
    float rho, e;
    transmittance_unit_ray((vec2(texel) + 0.5) / vec2(pc.width, pc.height), rho, e);
    vec3 t = exp(-optical_depth_to_top(rho, e));
    uint i = (texel.y * pc.width + texel.x) * 3u;
    result[i + 0u] = t.r;
    result[i + 1u] = t.g;
    result[i + 2u] = t.b;
}
