#version 450
/*
 * Evaluates the shared GLSL model at given points so tests can hold each
 * function against the fp64 reference (see sb_atmosphere_run_kernel).
 * One record of SB_PROBE_FLOATS floats per invocation, read then overwritten:
 *   in:  [0] h, [1] mu, [2] x_mu, [3] x_r, [4..5] a multiscattering texel, [6..7] an irradiance texel,
 *        [16] h, [17] mu of a ray toward the sun, [20] h, [21] mu_s of a multiscattering lookup
 *   out: [0..2]  transmittance_to_top(h, mu) (the exact quadrature)
 *        [3..5]  transmittance_lut_sample(h, mu)
 *        [6..7]  transmittance_unit_coords(h, mu)
 *        [8..9]  (h', mu') = transmittance_unit_geometry(x_mu, x_r)
 *        [10..11] transmittance_unit_coords(h', mu')
 *        [12..13] subtexel_coords(subtexel_geometry(ms texel, 32x32))
 *        [14..15] subtexel_coords(subtexel_geometry(irradiance texel, 64x16))
 *        [16..18] sun_transmittance(h, mu) of [16..17], from the bakes' sun table
 *        [20..22] multiscattering_lut_sample(h, mu_s) of [20..21]
 */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#include "atmosphere.glsl"

#define SB_PROBE_FLOATS 24

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(std430, set = 0, binding = SB_BINDING_OUTPUT) buffer Records { float records[]; };
layout(push_constant) uniform Push { sb_bake_push pc; };

void main()
{
    uint index = gl_GlobalInvocationID.y * pc.width + gl_GlobalInvocationID.x;
    if (gl_GlobalInvocationID.x >= pc.width || index >= pc.directions_mu)
        return;
    uint base = index * SB_PROBE_FLOATS;
    float h = records[base + 0u], mu = records[base + 1u];
    vec2 x = vec2(records[base + 2u], records[base + 3u]);
    uvec2 ms_texel = uvec2(records[base + 4u], records[base + 5u]);
    uvec2 irr_texel = uvec2(records[base + 6u], records[base + 7u]);

    vec3 sun = sun_transmittance(records[base + 16u], records[base + 17u]);
    vec3 psi = multiscattering_lut_sample(records[base + 20u], records[base + 21u]);

    float out_[SB_PROBE_FLOATS];
    vec3 exact = transmittance_to_top(h, mu);
    vec3 lut = transmittance_lut_sample(h, mu);
    vec2 coords = transmittance_unit_coords(h, mu);
    float h2, mu2;
    transmittance_unit_geometry(x, h2, mu2);
    vec2 back = transmittance_unit_coords(h2, mu2);
    uvec2 ms_size = uvec2(SB_MULTISCATTERING_SIZE), irr_size = uvec2(SB_IRRADIANCE_WIDTH, SB_IRRADIANCE_HEIGHT);
    vec2 ms = subtexel_geometry(ms_texel, ms_size);
    vec2 irr = subtexel_geometry(irr_texel, irr_size);
    vec2 ms_back = subtexel_coords(ms.x, ms.y, ms_size);
    vec2 irr_back = subtexel_coords(irr.x, irr.y, irr_size);

    out_[0] = exact.r; out_[1] = exact.g; out_[2] = exact.b;
    out_[3] = lut.r; out_[4] = lut.g; out_[5] = lut.b;
    out_[6] = coords.x; out_[7] = coords.y;
    out_[8] = h2; out_[9] = mu2;
    out_[10] = back.x; out_[11] = back.y;
    out_[12] = ms_back.x; out_[13] = ms_back.y;
    out_[14] = irr_back.x; out_[15] = irr_back.y;
    out_[16] = sun.r; out_[17] = sun.g; out_[18] = sun.b; out_[19] = 0.0;
    out_[20] = psi.r; out_[21] = psi.g; out_[22] = psi.b; out_[23] = 0.0;
    for (uint i = 0u; i < SB_PROBE_FLOATS; i++)
        records[base + i] = out_[i];
}
