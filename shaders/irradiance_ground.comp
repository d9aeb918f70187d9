#version 450
/* Irradiance on a horizontal surface at altitude h with the sun at mu_s,
 * 64x16, six channels:
 *   direct = E_sun T(h, mu_s) max(mu_s, 0)                  (the sun as a point)
 *   sky    = integral over the upper hemisphere of L(x, w) mu dw,
 *   L      = integral of T(x,y) [E_sun T_sun(y) (sigma_R(y) P_R(nu) + sigma_M(y) P_M(nu))
 *                                + (sigma_R(y) + sigma_M(y)) psi_ms(y)] dt.
 * Transmittance toward the sun for the direct part is integrated exactly; the
 * sky part reads the transmittance and multiple-scattering LUTs. */
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
    vec3 sun = atm.solar_irradiance.rgb;
    vec3 direct = mu_s > 0.0 ? sun * transmittance_to_top(h, mu_s) * mu_s : vec3(0.0);

    float sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    int n_mu = int(pc.directions_mu), n_phi = int(pc.directions_phi);
    vec3 sky = vec3(0.0);
    for (int k = 0; k < n_mu; k++) {
        float mu, w_mu;
        gauss_legendre(k, n_mu, 0.0, 1.0, mu, w_mu);
        float sin_v = sqrt(max(1.0 - mu * mu, 0.0));
        for (int p = 0; p < n_phi; p++) {
            float phi = (float(p) + 0.5) * PI / float(n_phi);
            float nu = clamp(sin_v * sin_s * cos(phi) + mu * mu_s, -1.0, 1.0);
            RayIntegrals ri = integrate_ray(h, mu, mu_s, nu, false, true);
            vec3 l = sun * (ri.sun_rayleigh * phase_rayleigh(nu) + ri.sun_mie * phase_mie(nu))
                   + ri.ms_rayleigh + ri.ms_mie;
            sky += (w_mu * 2.0 * PI / float(n_phi) * mu) * l;
        }
    }
    uint i = (texel.y * pc.width + texel.x) * 6u;
    result[i + 0u] = direct.r;
    result[i + 1u] = direct.g;
    result[i + 2u] = direct.b;
    result[i + 3u] = sky.r;
    result[i + 4u] = sky.g;
    result[i + 5u] = sky.b;
}
