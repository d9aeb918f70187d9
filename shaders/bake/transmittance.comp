#version 450
/* Transmittance to the top of the atmosphere, RGB fp32 (Hillaire 2020
 * parameterisation, see atmosphere.glsl). Built once per Gauss-Legendre
 * order SB_GL_ORDER (transmittance_glN; the bake's default is order 8 on
 * the pieces between kinks, at most 40 density samples a texel), and once
 * with SB_GL_ORDER 0 for the uniform rules of the push constants (config.h). */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#if SB_GL_ORDER > 0
#define SB_TRANSMITTANCE_GL_ORDER SB_GL_ORDER
#endif
#include "atmosphere.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { float result[]; };
layout(push_constant) uniform Push { sb_bake_push pc; };

void main()
{
    uvec2 texel = gl_GlobalInvocationID.xy;
    if (texel.x >= pc.width || texel.y >= pc.height)
        return;
    /* texel i of n at i / (n - 1) */
    uvec2 last = uvec2(pc.width, pc.height) - 1u;
    TransmittanceRay ray = transmittance_unit_ray_split(vec2(texel) / vec2(last), vec2(last - texel) / vec2(last));
#if SB_GL_ORDER > 0
    vec3 tau = optical_depth_to_top_gl(ray, int(pc.subdivisions));
#else
    vec3 tau = optical_depth_to_top_uniform(ray, int(pc.samples), pc.quadrature == SB_QUADRATURE_UNIFORM_0_3 ? 0.3 : 0.5,
                                            pc.quadrature == SB_QUADRATURE_TRAPEZOID);
#endif
    vec3 t = exp(-tau);
    uint i = (texel.y * pc.width + texel.x) * 3u;
    result[i + 0u] = t.r;
    result[i + 1u] = t.g;
    result[i + 2u] = t.b;
}
