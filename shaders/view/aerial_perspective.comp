#version 450
/* The aerial-perspective volume (Hillaire 2020, section 5.4): for 32 x 32
 * screen columns, the radiance scattered into the view ray and the
 * transmittance along it, from the camera to 32 distances, slice k (texel
 * centre w = (k + 0.5) / 32) at d = far * w^2 so slices crowd near the
 * camera. One invocation marches a column, each slice's segment by
 * Gauss-Legendre 4 (integrate_segment), so the slices share one integral.
 * The planet's shadow is included; shadows of the world are not. */
#extension GL_GOOGLE_include_directive : require
#ifndef SB_MOON
#define SB_MOONLESS /* the day's kernel; SB_MOON the night's (frame.glsl's moon_lights) */
#endif
#include "view_gpu.h"
#include "view.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_AERIAL_OUT, rgba16f) uniform writeonly image3D inscatter_out;
layout(set = 0, binding = SB_VIEW_BINDING_AERIAL_T_OUT, rgba16f) uniform writeonly image3D transmittance_out;

void main()
{
    uvec2 column = gl_GlobalInvocationID.xy;
    if (column.x >= SB_AERIAL_SIZE || column.y >= SB_AERIAL_SIZE)
        return;
    vec3 d = view_ray((vec2(column) + 0.5) / float(SB_AERIAL_SIZE));
    vec3 p = frame.camera_km.xyz;
    float r = length(p);
    float h = max(r - ground_radius(), 0.0);
    float mu = dot(p, d) / r;
    /* The volume serves cameras inside the atmosphere; above it, the scene
     * pass integrates per fragment. The moon, when it is in the sky, adds
     * its march's in-scattering to each slice. With the spectral products
     * each band of three wavelengths marches the column (its own integrals,
     * layer 1 + b: view.glsl), each slice's light summed through
     * band_to_rgb and its transmittance read as a colour. */
    vec3 l = frame.sun_direction.xyz, m = frame.moon_direction.xyz;
    float mu_s = dot(p, l) / r, nu = dot(d, l), mu_m = dot(p, m) / r, nu_m = dot(d, m);
    float p_r = phase_rayleigh(nu), p_m = phase_mie(nu), q_r = phase_rayleigh(nu_m), q_m = phase_mie(nu_m);
    const int bands = SB_VIEW_BANDS ? SB_SPECTRAL_BANDS : 1;
    RayIntegrals ri[SB_SPECTRAL_BANDS], rm[SB_SPECTRAL_BANDS];
    /* with the orders product, orders 2 and up between the eye and each
     * slice from the table (orders_between) instead of psi_ms's march */
    bool ms = !orders_present();
    vec3 eye[SB_SPECTRAL_BANDS], eye_m[SB_SPECTRAL_BANDS];
    for (int b = 0; b < bands; b++) {
        atm_band = SB_VIEW_BANDS ? 1 + b : 0;
        ri[b] = ray_integrals_begin();
        rm[b] = ray_integrals_begin();
        eye[b] = ms ? vec3(0.0) : orders_eye(h, mu, mu_s, nu);
        eye_m[b] = vec3(0.0);
        for (int i = 0; i < moon_lights() && !ms; i++)
            eye_m[b] = orders_eye(h, mu, mu_m, nu_m);
    }
    float t0 = 0.0;
    for (int k = 0; k < SB_AERIAL_SIZE; k++) {
        float w = (float(k) + 0.5) / float(SB_AERIAL_SIZE);
        float t1 = frame.aerial.x * w * w;
        vec3 L = vec3(0.0), L_moon = vec3(0.0), band_t[SB_SPECTRAL_BANDS];
        for (int b = 0; b < bands; b++) {
            atm_band = SB_VIEW_BANDS ? 1 + b : 0;
            vec3 sun = atm.solar_irradiance.rgb, moon = sun * frame.moon_light.rgb;
            integrate_segment(ri[b], h, mu, mu_s, nu, t0, t1, ms);
            vec3 Lb = sun * (ri[b].sun_rayleigh * p_r + ri[b].sun_mie * p_m) + ri[b].ms_rayleigh + ri[b].ms_mie;
            if (!ms)
                Lb += orders_between(eye[b], h, mu, mu_s, nu, t1, exp(-ri[b].tau));
            for (int i = 0; i < moon_lights(); i++) {
                integrate_segment(rm[b], h, mu, mu_m, nu_m, t0, t1, ms);
                if (SB_VIEW_BANDS) { /* the moon's colour on the band's sum */
                    vec3 Lm = sun * (rm[b].sun_rayleigh * q_r + rm[b].sun_mie * q_m) + rm[b].ms_rayleigh + rm[b].ms_mie;
                    if (!ms)
                        Lm += orders_between(eye_m[b], h, mu, mu_m, nu_m, t1, exp(-rm[b].tau));
                    L_moon += band_to_rgb(b) * Lm;
                    continue;
                }
                Lb += moon * (rm[b].sun_rayleigh * q_r + rm[b].sun_mie * q_m) +
                      frame.moon_light.rgb * (rm[b].ms_rayleigh + rm[b].ms_mie);
                if (!ms)
                    Lb += frame.moon_light.rgb * orders_between(eye_m[b], h, mu, mu_m, nu_m, t1, exp(-rm[b].tau));
            }
            L += SB_VIEW_BANDS ? band_to_rgb(b) * Lb : Lb;
            band_t[b] = exp(-ri[b].tau);
        }
        atm_band = 0;
        L += frame.moon_light.rgb * L_moon;
        t0 = t1;
        imageStore(inscatter_out, ivec3(column, k), vec4(fp16_safe(L * frame.aerial.y), 1.0));
        imageStore(transmittance_out, ivec3(column, k),
                   vec4(SB_VIEW_BANDS ? bands_transmittance_rgb(band_t) : band_t[0], 1.0));
    }
}
