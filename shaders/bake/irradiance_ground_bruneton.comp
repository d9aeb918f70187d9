#version 450
/* An anchor for skybake bench, not a product's kernel: irradiance_ground as
 * Bruneton & Neyret's 2017 reference implementation integrates it
 * (ComputeDirectIrradiance, ComputeIndirectIrradiance and
 * ComputeSingleScattering of their functions.glsl), at skybake's texels
 * (subtexel_geometry), so that its error is measured at the same points as
 * ours:
 * - sky: the upper hemisphere by the midpoint rule, directions_mu zenith
 *   angles (theta_j = (j + 1/2) pi / (2 n)) by directions_phi azimuths
 *   (phi_i = (i + 1/2) 2 pi / n); theirs is 16 x 64, of L cos(theta)
 *   sin(theta) dtheta dphi;
 * - each direction's radiance by the trapezoidal rule of `samples`
 *   intervals (their 50) from the point to the top, with the transmittance
 *   to each sample the ratio of two bilinear lookups of the baked
 *   transmittance LUT (clamped to 1), and the sun's from the LUT too;
 * - the radiance is skybake's definition of it (docs/pack.md): single
 *   scattering with the Rayleigh and Mie phase functions plus psi_ms
 *   times the scattering coefficient, psi_ms read from the baked
 *   multiscattering LUT (their own multiple scattering, order by order into
 *   4D tables, is not what irradiance_ground holds);
 * - direct: the sun's irradiance times the LUT's transmittance toward it
 *   times mu_s.
 * One workgroup of 64 per texel, each invocation every 64th direction;
 * invocation 0 sums in a fixed order. */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#define SB_SUN_TRANSMITTANCE_LUT
#include "atmosphere.glsl"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { sb_bake_push pc; };
layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { float result[]; };

shared vec3 sky_sum[64];

/* The radiance reaching altitude h from direction mu (> 0: never the ground). */
vec3 radiance(float h, float mu, float mu_s, float nu)
{
    float r0 = ground_radius() + h;
    float dx = distance_to_top(h, mu) / float(pc.samples);
    vec3 t_origin = transmittance_lut_sample(h, mu);
    vec3 rayleigh = vec3(0.0), mie = vec3(0.0), ms = vec3(0.0);
    for (uint i = 0u; i <= pc.samples; i++) {
        float d = float(i) * dx;
        float hd = altitude_along(h, mu, d);
        float rd = ground_radius() + hd;
        float mu_d = clamp((r0 * mu + d) / rd, -1.0, 1.0);
        float mu_sd = clamp((r0 * mu_s + d * nu) / rd, -1.0, 1.0);
        vec3 t = min(t_origin / max(transmittance_lut_sample(hd, mu_d), vec3(1e-30)), vec3(1.0));
        float weight = i == 0u || i == pc.samples ? 0.5 : 1.0;
        Medium m = medium_at(hd);
        vec3 sun = t * sun_transmittance(hd, mu_sd) * weight;
        rayleigh += sun * m.scattering_rayleigh;
        mie += sun * m.scattering_mie;
        ms += t * weight * (m.scattering_rayleigh + m.scattering_mie) * multiscattering_lut_sample(hd, mu_sd);
    }
    vec3 single = atm.solar_irradiance.rgb * (rayleigh * phase_rayleigh(nu) + mie * phase_mie(nu));
    return (single + ms) * dx;
}

void main()
{
    uvec2 texel = gl_WorkGroupID.xy;
    vec2 geometry = subtexel_geometry(texel, uvec2(pc.width, pc.height));
    float h = geometry.x, mu_s = geometry.y;
    float sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    uint n_theta = pc.directions_mu, n_phi = pc.directions_phi;
    float dtheta = 0.5 * PI / float(n_theta), dphi = 2.0 * PI / float(n_phi);

    uint k = gl_LocalInvocationIndex;
    vec3 sky = vec3(0.0);
    for (uint d = k; d < n_theta * n_phi; d += 64u) {
        float theta = (float(d / n_phi) + 0.5) * dtheta, phi = (float(d % n_phi) + 0.5) * dphi;
        float mu = cos(theta), sin_v = sin(theta);
        float nu = clamp(sin_v * sin_s * cos(phi) + mu * mu_s, -1.0, 1.0);
        sky += radiance(h, mu, mu_s, nu) * (mu * sin_v * dtheta * dphi);
    }
    sky_sum[k] = sky;
    barrier();
    if (k != 0u)
        return;
    sky = vec3(0.0);
    for (uint i = 0u; i < 64u; i++)
        sky += sky_sum[i];
    vec3 direct = mu_s > 0.0 ? atm.solar_irradiance.rgb * sun_transmittance(h, mu_s) * mu_s : vec3(0.0);
    uint o = (texel.y * pc.width + texel.x) * 6u;
    result[o + 0u] = direct.r;
    result[o + 1u] = direct.g;
    result[o + 2u] = direct.b;
    result[o + 3u] = sky.r;
    result[o + 4u] = sky.g;
    result[o + 5u] = sky.b;
}
