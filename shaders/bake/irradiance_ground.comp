#version 450
/* Irradiance on a horizontal surface at altitude h with the sun at mu_s,
 * 64x16, six channels:
 *   direct = E_sun T(h, mu_s) max(mu_s, 0)                  (the sun as a point)
 *   sky    = integral over the upper hemisphere of L(x, w) mu dw,
 *   L      = integral of T(x,y) [E_sun T_sun(y) (sigma_R(y) P_R(nu) + sigma_M(y) P_M(nu))
 *                                + (sigma_R(y) + sigma_M(y)) psi_ms(y)] dt.
 * Transmittance toward the sun is integrated exactly, the multiple
 * scattering read from its LUT. One workgroup per texel (sphere.glsl). */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#define SB_RAY_OZONE_CORNERS
#define SB_RAY_LEVELS_DOUBLING /* with the corners, no less accurate (docs/accuracy.md) */
#include "atmosphere.glsl"
#include "sphere.glsl"

layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { float result[]; };

void main()
{
    uvec2 texel = sphere_texel();
    vec2 geometry = subtexel_geometry(texel, uvec2(pc.width, pc.height));
    float h = geometry.x, mu_s = geometry.y;
    vec3 sun = atm.solar_irradiance.rgb;
    float sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    sphere_init(pc.directions_mu, pc.directions_phi, true);
    SpherePieces pieces = sphere_pieces(h, false, mu_s, false); /* Mie's peak: on the cap */
    SphereCap cap = sphere_cap(h, false, mu_s);

    sphere_begin();
    uint count = sphere_direction_count(pieces, pc.directions_mu, pc.directions_phi);
    uint total = count + sphere_cap_direction_count(cap, pc.directions_mu, pc.directions_phi);
    /* One integrate_ray for both grids, so that the invocations integrating
     * the cap's directions and those on the zenith grid run it together. */
    for (uint d = sphere_first_direction(); d < sphere_end_direction(total); d += SB_SPHERE_THREADS) {
        bool on_cap = d >= count; /* Mie single scattering's peak */
        SphereDirection s;
        float nu;
        if (on_cap) {
            CapDirection cd = sphere_cap_direction(cap, d - count, pc.directions_mu, pc.directions_phi);
            if (cd.phase_weight <= 0.0)
                continue;
            s.mu = cd.mu;
            s.weight = cd.phase_weight;
            nu = cd.nu;
        } else {
            s = sphere_direction(pieces, d, pc.directions_mu, pc.directions_phi);
            float sin_v = sqrt(max(1.0 - s.mu * s.mu, 0.0));
            nu = clamp(sin_v * sin_s * s.cos_phi + s.mu * mu_s, -1.0, 1.0);
        }
        RayIntegrals ri = integrate_ray(h, s.mu, mu_s, nu, false, !on_cap);
        if (on_cap) {
            sphere_add3(0u, s.weight * s.mu * sun * ri.sun_mie);
            continue;
        }
        float mie = phase_mie(nu) * (1.0 - sphere_cap_window(false, nu));
        vec3 l = sun * (ri.sun_rayleigh * phase_rayleigh(nu) + ri.sun_mie * mie) + ri.ms_rayleigh + ri.ms_mie;
        sphere_add3(0u, s.weight * s.mu * l);
    }
    if (!sphere_finish(3u) || gl_LocalInvocationIndex != 0u)
        return;
    vec3 sky = sphere_sum3(0u);
    vec3 direct = mu_s > 0.0 ? sun * transmittance_to_top(h, mu_s) * mu_s : vec3(0.0);
    uint i = (texel.y * pc.width + texel.x) * 6u;
    result[i + 0u] = direct.r;
    result[i + 1u] = direct.g;
    result[i + 2u] = direct.b;
    result[i + 3u] = sky.r;
    result[i + 4u] = sky.g;
    result[i + 5u] = sky.b;
}
