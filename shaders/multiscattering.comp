#version 450
/* Hillaire 2020's multiple-scattering transfer psi_ms(h, mu_s), 32x32 RGB,
 * including the ground bounce:
 *   L2  = 1/(4 pi) * integral over the sphere of L'(x, w) dw,
 *   L'  = integral of T(x,y) sigma_s(y) T_sun(y) / (4 pi) dt
 *         + [ray hits ground] T(x,p) albedo/pi max(mu_s(p), 0) T_sun(p),
 *   f   = 1/(4 pi) * integral over the sphere of integral of T(x,y) sigma_s(y) dt dw,
 *   psi = E_sun L2 / (1 - f).
 * Directions: Gauss-Legendre in mu on [-1, mu_horizon] and [mu_horizon, 1]
 * (the integrand jumps at the horizon), midpoint in azimuth (the integrand is
 * even in azimuth about the sun's plane: [0, pi] twice). */
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
    float sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    int n_mu = int(pc.directions_mu), n_phi = int(pc.directions_phi);

    vec3 l2 = vec3(0.0), f = vec3(0.0);
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
                RayIntegrals ri = integrate_ray(h, mu, mu_s, nu, toward_ground, false);
                vec3 lp = (ri.sun_rayleigh + ri.sun_mie) / (4.0 * PI);
                if (toward_ground) {
                    float mu_sp = clamp((r * mu_s + ri.t_end * nu) / ground_radius(), -1.0, 1.0);
                    if (mu_sp > 0.0)
                        lp += ri.transmittance * atm.ground_albedo.rgb / PI * mu_sp * sun_transmittance(0.0, mu_sp);
                }
                l2 += w * lp;
                f += w * ri.scattering;
            }
        }
    }
    l2 /= 4.0 * PI;
    f /= 4.0 * PI;
    vec3 psi = atm.solar_irradiance.rgb * l2 / (1.0 - f);
    uint i = (texel.y * pc.width + texel.x) * 3u;
    result[i + 0u] = psi.r;
    result[i + 1u] = psi.g;
    result[i + 2u] = psi.b;
}
