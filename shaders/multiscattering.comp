#version 450
/* Hillaire 2020's multiple-scattering transfer psi_ms(h, mu_s), 32x32 RGB,
 * including the ground bounce:
 *   L2  = 1/(4 pi) * integral over the sphere of L'(x, w) dw,
 *   L'  = integral of T(x,y) sigma_s(y) T_sun(y) / (4 pi) dt
 *         + [ray hits ground] T(x,p) albedo/pi max(mu_s(p), 0) T_sun(p),
 *   f   = 1/(4 pi) * integral over the sphere of integral of T(x,y) sigma_s(y) dt dw,
 *   psi = E_sun L2 / (1 - f).
 * One workgroup per texel (sphere.glsl). */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#define SB_RAY_OZONE_CORNERS
#include "atmosphere.glsl"
#include "sphere.glsl"

layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { float result[]; };

void main()
{
    uvec2 texel = gl_WorkGroupID.xy;
    vec2 geometry = subtexel_geometry(texel, uvec2(pc.width, pc.height));
    float h = geometry.x, mu_s = geometry.y;
    float r = ground_radius() + h;
    float sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    sphere_init(pc.directions_mu, pc.directions_phi, false);
    SpherePieces pieces = sphere_pieces(h, true, mu_s, false);

    sphere_begin();
    uint count = sphere_direction_count(pieces, pc.directions_mu, pc.directions_phi);
    for (uint d = sphere_first_direction(); d < sphere_end_direction(count); d += SB_SPHERE_THREADS) {
        SphereDirection s = sphere_direction(pieces, d, pc.directions_mu, pc.directions_phi);
        float sin_v = sqrt(max(1.0 - s.mu * s.mu, 0.0));
        float nu = clamp(sin_v * sin_s * s.cos_phi + s.mu * mu_s, -1.0, 1.0);
        RayIntegrals ri = integrate_ray(h, s.mu, mu_s, nu, s.toward_ground, false);
        vec3 lp = (ri.sun_rayleigh + ri.sun_mie) / (4.0 * PI);
        if (s.toward_ground) {
            float mu_sp = clamp((r * mu_s + ri.t_end * nu) / ground_radius(), -1.0, 1.0);
            if (mu_sp > 0.0)
                lp += ri.transmittance * atm.ground_albedo.rgb / PI * mu_sp * sun_transmittance(0.0, mu_sp);
        }
        sphere_add3(0u, s.weight * lp);
        sphere_add3(3u, s.weight * ri.scattering);
    }
    if (!sphere_finish(6u) || gl_LocalInvocationIndex != 0u)
        return;
    vec3 l2 = sphere_sum3(0u) / (4.0 * PI);
    vec3 f = sphere_sum3(3u) / (4.0 * PI);
    vec3 psi = atm.solar_irradiance.rgb * l2 / (1.0 - f);
    uint i = (texel.y * pc.width + texel.x) * 3u;
    result[i + 0u] = psi.r;
    result[i + 1u] = psi.g;
    result[i + 2u] = psi.b;
}
