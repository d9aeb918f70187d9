// The sky's radiance along a ray (atmosphere.glsl's integrals of the
// baked LUTs): what skyview's sky and the reflection probes' capture see.
#ifndef SB_SKY_RADIANCE_GLSL
#define SB_SKY_RADIANCE_GLSL

#include "config.h"
#include "atmosphere.glsl"

#ifdef SB_ORDERS_TEXTURE
/* The orders product, where the includer reads it (view.glsl). */
bool orders_present();
vec3 orders_sky(float h, float mu, float mu_s, float nu, bool ground);
vec3 orders_ground_sky(float mu_s);
#endif

/* Radiance of the sky along a ray from altitude h (km) with view cosine mu,
 * sun cosine mu_s and view-sun cosine nu: single scattering with the baked
 * transmittance toward the sun, multiple scattering from psi_ms (or, where
 * the pack has them, orders 2 and up from the orders product), and the lit
 * ground where the ray ends on it. The sun itself is not included. */
vec3 sky_radiance(float h, float mu, float mu_s, float nu)
{
    bool ground = ray_hits_ground(h, mu);
#ifdef SB_ORDERS_TEXTURE
    bool orders = orders_present();
#else
    const bool orders = false;
#endif
    RayIntegrals ri = integrate_ray(h, mu, mu_s, nu, ground, !orders);
    vec3 sun = atm.solar_irradiance.rgb;
    vec3 L = sun * (ri.sun_rayleigh * phase_rayleigh(nu) + ri.sun_mie * phase_mie(nu)) + ri.ms_rayleigh + ri.ms_mie;
#ifdef SB_ORDERS_TEXTURE
    if (orders)
        L += orders_sky(h, mu, mu_s, nu, ground);
#endif
    if (ground) {
        float r = ground_radius() + h;
        float mu_sp = clamp((r * mu_s + ri.t_end * nu) / ground_radius(), -1.0, 1.0);
        vec3 E = ground_irradiance_sample(mu_sp);
#ifdef SB_ORDERS_TEXTURE
        if (orders) /* the sky's part from every order instead of psi_ms's */
            E += orders_ground_sky(mu_sp) - ground_sky_irradiance_sample(mu_sp);
#endif
        L += ri.transmittance * atm.ground_albedo.rgb / PI * max(E, vec3(0.0));
    }
    return L;
}

#endif
