#version 450
/* Sky light reaching a point in the air, for lighting clouds and haze:
 * the mean radiance over the whole sphere, (1/4pi) * integral of L(x, w) dw,
 * at altitude h with the sun at mu_s, 64x16, nine channels split by what
 * sent the light last:
 *   rayleigh = from Rayleigh scattering: E_sun T_sun sigma_R P_R(nu) + sigma_R psi_ms
 *   mie      = from Mie scattering:      E_sun T_sun sigma_M P_M(nu) + sigma_M psi_ms
 *   ground   = the ground seen directly: T(x,p) albedo/pi E_ground(p)
 * each integrated along the ray with T(x,y). The direct sun is excluded.
 * For an isotropic scatterer, in-scattered radiance = sigma_s * (sum of the
 * three); the runtime may weight them separately. */
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
    float mu_s = 2.0 * texel_unit(texel.x, pc.width) - 1.0;
    float h = atmosphere_thickness() * texel_unit(texel.y, pc.height);
    float r = ground_radius() + h;
    float mu_horizon = -horizon_distance(h) / r;
    vec3 sun = atm.solar_irradiance.rgb;
    float sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    int n_mu = int(pc.directions_mu), n_phi = int(pc.directions_phi);

    vec3 rayleigh = vec3(0.0), mie = vec3(0.0), ground = vec3(0.0);
    for (int part = 0; part < 2; part++) {
        bool toward_ground = part == 1;
        float a = toward_ground ? -1.0 : mu_horizon, b = toward_ground ? mu_horizon : 1.0;
        for (int k = 0; k < n_mu; k++) {
            float mu, w_mu;
            gauss_legendre(k, n_mu, a, b, mu, w_mu);
            float sin_v = sqrt(max(1.0 - mu * mu, 0.0));
            for (int p = 0; p < n_phi; p++) {
                float phi = (float(p) + 0.5) * PI / float(n_phi);
                float w = w_mu * 2.0 * PI / float(n_phi);
                float nu = clamp(sin_v * sin_s * cos(phi) + mu * mu_s, -1.0, 1.0);
                RayIntegrals ri = integrate_ray(h, mu, mu_s, nu, toward_ground, true);
                rayleigh += w * (sun * ri.sun_rayleigh * phase_rayleigh(nu) + ri.ms_rayleigh);
                mie += w * (sun * ri.sun_mie * phase_mie(nu) + ri.ms_mie);
                if (toward_ground) {
                    float mu_sp = clamp((r * mu_s + ri.t_end * nu) / ground_radius(), -1.0, 1.0);
                    ground += w * ri.transmittance * atm.ground_albedo.rgb / PI * ground_irradiance_sample(mu_sp);
                }
            }
        }
    }
    float norm = 1.0 / (4.0 * PI);
    rayleigh *= norm;
    mie *= norm;
    ground *= norm;
    uint i = (texel.y * pc.width + texel.x) * 9u;
    result[i + 0u] = rayleigh.r;
    result[i + 1u] = rayleigh.g;
    result[i + 2u] = rayleigh.b;
    result[i + 3u] = mie.r;
    result[i + 4u] = mie.g;
    result[i + 5u] = mie.b;
    result[i + 6u] = ground.r;
    result[i + 7u] = ground.g;
    result[i + 8u] = ground.b;
}
