/*
 * Aerial perspective between the camera and a point (Hillaire 2020, section
 * 5.4): the aerial-perspective volume inside its range, else the same
 * integral along the ray (cameras above the atmosphere, far points). For
 * the scene and the clouds. A shader that defines SB_AERIAL_VOLUME_ONLY
 * leaves the ray's integral out: its caller must know that the camera is in
 * the atmosphere and every point within the volume's range (llvmpipe runs
 * the integral's code for every fragment even when none takes it).
 */
#ifndef SB_AERIAL_GLSL
#define SB_AERIAL_GLSL

#include "view_gpu.h"
#include "view.glsl"

layout(set = 0, binding = SB_VIEW_BINDING_AERIAL) uniform sampler3D aerial_inscatter;
layout(set = 0, binding = SB_VIEW_BINDING_AERIAL_T) uniform sampler3D aerial_transmittance;

/* In-scattered radiance (rgb, scaled like the frame) and transmittance from
 * the camera to a point `offset` metres away, seen at screen position uv
 * ([0, 1]^2, the volume's columns). */
void aerial_perspective(vec2 uv, vec3 offset, out vec3 inscatter, out vec3 transmittance)
{
    float d_km = length(offset) * 1e-3;
    float far_km = frame.aerial.x;
#ifndef SB_AERIAL_VOLUME_ONLY
    if (frame.camera_km.w < atmosphere_thickness() && d_km <= far_km)
#endif
    {
        float w = sqrt(d_km / far_km);
        const float w0 = 0.5 / float(SB_AERIAL_SIZE);
        vec3 uvw = vec3(uv, max(w, w0));
        inscatter = textureLod(aerial_inscatter, uvw, 0.0).rgb;
        transmittance = textureLod(aerial_transmittance, uvw, 0.0).rgb;
        if (w < w0) { /* before the first slice, linear in distance */
            float f = (w / w0) * (w / w0);
            inscatter *= f;
            transmittance = mix(vec3(1.0), transmittance, f);
        }
        return;
    }
#ifndef SB_AERIAL_VOLUME_ONLY
    vec3 d = normalize(offset);
    vec3 p = frame.camera_km.xyz;
    float entry = atmosphere_entry(p, d);
    inscatter = vec3(0.0);
    transmittance = vec3(1.0);
    if (entry < 0.0 || entry >= d_km)
        return;
    vec3 p0 = p + d * entry;
    float r0 = length(p0);
    float h0 = max(r0 - ground_radius(), 0.0);
    float mu = dot(p0, d) / r0;
    /* with the spectral products, band by band (view.glsl) */
    const int bands = SB_VIEW_BANDS ? SB_SPECTRAL_BANDS : 1;
    bool ms = !orders_present(); /* else orders 2 and up from the orders product */
    vec3 L = vec3(0.0), L_moon = vec3(0.0), band_t[SB_SPECTRAL_BANDS];
    for (int b = 0; b < bands; b++) {
        atm_band = SB_VIEW_BANDS ? 1 + b : 0;
        vec3 l = frame.sun_direction.xyz;
        float mu_s = dot(p0, l) / r0, nu = dot(d, l);
        RayIntegrals ri = ray_integrals_begin();
        integrate_ray_to(ri, h0, mu, mu_s, nu, d_km - entry, ms);
        vec3 Lb = atm.solar_irradiance.rgb * (ri.sun_rayleigh * phase_rayleigh(nu) + ri.sun_mie * phase_mie(nu)) +
                  ri.ms_rayleigh + ri.ms_mie;
        if (!ms)
            Lb += orders_between(orders_eye(h0, mu, mu_s, nu), h0, mu, mu_s, nu, d_km - entry, ri.transmittance);
        band_t[b] = ri.transmittance;
        for (int i = 0; i < moon_lights(); i++) {
            l = frame.moon_direction.xyz;
            mu_s = dot(p0, l) / r0;
            nu = dot(d, l);
            ri = ray_integrals_begin();
            integrate_ray_to(ri, h0, mu, mu_s, nu, d_km - entry, ms);
            vec3 Lm = atm.solar_irradiance.rgb * (ri.sun_rayleigh * phase_rayleigh(nu) + ri.sun_mie * phase_mie(nu)) +
                      ri.ms_rayleigh + ri.ms_mie;
            if (!ms)
                Lm += orders_between(orders_eye(h0, mu, mu_s, nu), h0, mu, mu_s, nu, d_km - entry, ri.transmittance);
            if (SB_VIEW_BANDS)
                L_moon += band_to_rgb(b) * Lm;
            else
                Lb += Lm * frame.moon_light.rgb;
        }
        L += SB_VIEW_BANDS ? band_to_rgb(b) * Lb : Lb;
    }
    atm_band = 0;
    L += frame.moon_light.rgb * L_moon;
    transmittance = SB_VIEW_BANDS ? bands_transmittance_rgb(band_t) : band_t[0];
    inscatter = L * frame.aerial.y;
#endif
}

#endif
