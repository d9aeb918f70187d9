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
     * its march's in-scattering to each slice. */
    vec3 l = frame.sun_direction.xyz, m = frame.moon_direction.xyz;
    float mu_s = dot(p, l) / r, nu = dot(d, l), mu_m = dot(p, m) / r, nu_m = dot(d, m);
    vec3 sun = atm.solar_irradiance.rgb, moon = sun * frame.moon_light.rgb;
    float p_r = phase_rayleigh(nu), p_m = phase_mie(nu), q_r = phase_rayleigh(nu_m), q_m = phase_mie(nu_m);
    RayIntegrals ri = ray_integrals_begin(), rm = ray_integrals_begin();
    /* with the orders product, orders 2 and up between the eye and each
     * slice from the table (orders_between) instead of psi_ms's march */
    bool ms = !orders_present();
    vec3 eye = ms ? vec3(0.0) : orders_eye(h, mu, mu_s, nu), eye_m = vec3(0.0);
    for (int i = 0; i < moon_lights() && !ms; i++)
        eye_m = orders_eye(h, mu, mu_m, nu_m);
    float t0 = 0.0;
    for (int k = 0; k < SB_AERIAL_SIZE; k++) {
        float w = (float(k) + 0.5) / float(SB_AERIAL_SIZE);
        float t1 = frame.aerial.x * w * w;
        integrate_segment(ri, h, mu, mu_s, nu, t0, t1, ms);
        vec3 L = sun * (ri.sun_rayleigh * p_r + ri.sun_mie * p_m) + ri.ms_rayleigh + ri.ms_mie;
        if (!ms)
            L += orders_between(eye, h, mu, mu_s, nu, t1, exp(-ri.tau));
        for (int i = 0; i < moon_lights(); i++) {
            integrate_segment(rm, h, mu, mu_m, nu_m, t0, t1, ms);
            L += moon * (rm.sun_rayleigh * q_r + rm.sun_mie * q_m) + frame.moon_light.rgb * (rm.ms_rayleigh + rm.ms_mie);
            if (!ms)
                L += frame.moon_light.rgb * orders_between(eye_m, h, mu, mu_m, nu_m, t1, exp(-rm.tau));
        }
        t0 = t1;
        imageStore(inscatter_out, ivec3(column, k), vec4(fp16_safe(L * frame.aerial.y), 1.0));
        imageStore(transmittance_out, ivec3(column, k), vec4(exp(-ri.tau), 1.0));
    }
}
