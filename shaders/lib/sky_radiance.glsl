// The sky's radiance along a ray (atmosphere.glsl's integrals of the
// baked LUTs): what skyview's sky and the reflection probes' capture see.
#ifndef SB_SKY_RADIANCE_GLSL
#define SB_SKY_RADIANCE_GLSL

#include "config.h"
#include "atmosphere.glsl"

/* Radiance of the sky along a ray from altitude h (km) with view cosine mu,
 * sun cosine mu_s and view-sun cosine nu: single scattering with the baked
 * transmittance toward the sun, multiple scattering from psi_ms, and the
 * lit ground where the ray ends on it. The sun itself is not included. */
vec3 sky_radiance(float h, float mu, float mu_s, float nu)
{
    bool ground = ray_hits_ground(h, mu);
    RayIntegrals ri = integrate_ray(h, mu, mu_s, nu, ground, true);
    vec3 sun = atm.solar_irradiance.rgb;
    vec3 L = sun * (ri.sun_rayleigh * phase_rayleigh(nu) + ri.sun_mie * phase_mie(nu)) + ri.ms_rayleigh + ri.ms_mie;
    if (ground) {
        float r = ground_radius() + h;
        float mu_sp = clamp((r * mu_s + ri.t_end * nu) / ground_radius(), -1.0, 1.0);
        L += ri.transmittance * atm.ground_albedo.rgb / PI * ground_irradiance_sample(mu_sp);
    }
    return L;
}

#endif
