#version 450
/* An anchor for skybake bench, not a product's kernel: the multiple-
 * scattering LUT as Hillaire 2020 (section 5.5 and his published demo)
 * computes it, at skybake's texels (subtexel_geometry), so its error is
 * measured at the same points as ours:
 * - directions: the sphere in directions_mu x directions_phi cells (his
 *   8 x 8 = 64), uniform in cos(zenith) and in azimuth, one at each cell's
 *   centre, one invocation each (beyond SB_ANCHOR_THREADS, invocation i
 *   walks directions i, i + SB_ANCHOR_THREADS, ... and sums them in that
 *   order: the bench's rows with more directions show how the method
 *   converges);
 * - each ray marched to the ground or the top in `samples` equal steps (his
 *   20), sampled at 0.3 of each step, each step integrated analytically
 *   with its sample's medium: (S - S e^(-sigma_t dt)) / sigma_t;
 * - the sun's transmittance at each sample read bilinearly from the baked
 *   transmittance LUT, zero where the planet hides the sun;
 * - the lit ground, albedo / pi max(mu_s, 0) T_sun, where a ray ends on it;
 * - psi_ms = E_sun L2 / (1 - f), L2 and f the means over the directions of
 *   the isotropically scattered light and of the scattering (his
 *   "MultiScatAs1"), as multiscattering.comp defines them.
 * One workgroup of SB_ANCHOR_THREADS per texel; invocation 0 sums their
 * sums in a fixed order. */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#define SB_SUN_TRANSMITTANCE_LUT
#include "atmosphere.glsl"

layout(local_size_x = SB_ANCHOR_THREADS) in;
layout(push_constant) uniform Push { sb_bake_push pc; };
layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { float result[]; };

shared vec3 light_sum[SB_ANCHOR_THREADS];
shared vec3 scattering_sum[SB_ANCHOR_THREADS];

void main()
{
    uvec2 texel = gl_WorkGroupID.xy;
    vec2 geometry = subtexel_geometry(texel, uvec2(pc.width, pc.height));
    float h = geometry.x, mu_s = geometry.y;
    float r0 = ground_radius() + h;
    float sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));

    uint i = gl_LocalInvocationIndex;
    uint count = pc.directions_mu * pc.directions_phi;
    vec3 light = vec3(0.0), scattering = vec3(0.0);
    for (uint d = i; d < count; d += SB_ANCHOR_THREADS) {
        float a = (float(d / pc.directions_mu) + 0.5) / float(pc.directions_phi);
        float b = (float(d % pc.directions_mu) + 0.5) / float(pc.directions_mu);
        float phi = 2.0 * PI * a;
        float mu = 1.0 - 2.0 * b;
        float sin_v = sqrt(max(1.0 - mu * mu, 0.0));
        float nu = clamp(sin_v * sin_s * cos(phi) + mu * mu_s, -1.0, 1.0);
        bool ground = ray_hits_ground(h, mu);
        float t_max = ground ? distance_to_ground(h, mu) : distance_to_top(h, mu);
        float dt = t_max / float(pc.samples);
        vec3 throughput = vec3(1.0);
        for (uint s = 0u; s < pc.samples; s++) {
            float t = (float(s) + 0.3) * dt;
            float hs = altitude_along(h, mu, t);
            float mus = clamp((r0 * mu_s + t * nu) / (ground_radius() + hs), -1.0, 1.0);
            Medium m = medium_at(hs);
            vec3 sigma_s = m.scattering_rayleigh + m.scattering_mie;
            vec3 step_t = exp(-m.extinction * dt);
            vec3 safe = max(m.extinction, vec3(1e-30));
            vec3 source = sigma_s * sun_transmittance(hs, mus) / (4.0 * PI);
            light += throughput * (source - source * step_t) / safe;
            scattering += throughput * (sigma_s - sigma_s * step_t) / safe;
            throughput *= step_t;
        }
        if (ground) {
            float mu_sp = clamp((r0 * mu_s + t_max * nu) / ground_radius(), -1.0, 1.0);
            light += throughput * atm.ground_albedo.rgb / PI * max(mu_sp, 0.0) * sun_transmittance(0.0, mu_sp);
        }
    }
    light_sum[i] = light;
    scattering_sum[i] = scattering;
    barrier();
    if (i != 0u)
        return;
    vec3 l2 = vec3(0.0), f = vec3(0.0);
    for (uint k = 0u; k < min(count, uint(SB_ANCHOR_THREADS)); k++) {
        l2 += light_sum[k];
        f += scattering_sum[k];
    }
    l2 /= float(count);
    f /= float(count);
    vec3 psi = atm.solar_irradiance.rgb * l2 / (1.0 - f);
    uint o = (texel.y * pc.width + texel.x) * 3u;
    result[o + 0u] = psi.r;
    result[o + 1u] = psi.g;
    result[o + 2u] = psi.b;
}
