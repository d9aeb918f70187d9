#version 450
/* The aerial-perspective volume (Hillaire 2020, section 5.4): for 32 x 32
 * screen columns, the radiance scattered into the view ray and the
 * transmittance along it, from the camera to 32 distances, slice k (texel
 * centre w = (k + 0.5) / 32) at d = far * w^2 so slices crowd near the
 * camera. One invocation marches a column, each slice's segment by
 * Gauss-Legendre 4 (integrate_segment), so the slices share one integral.
 * With the spectral products one invocation marches a column's band (the
 * workgroup's depth is SB_VIEW_CONSTANT_BAND_LANES), and the band 0
 * invocation sums each slice's bands: 1024 columns each marching four
 * bands left a GPU mostly idle (0.31 ms at 1080p on the H200, 0.12 so).
 * The four bands of a column are a quad of a subgroup where quads can
 * share values (SB_AERIAL_QUADS); elsewhere they meet in workgroup memory
 * at a barrier a slice. The planet's shadow is included; shadows of the
 * world are not. */
#extension GL_GOOGLE_include_directive : require
#ifdef SB_AERIAL_QUADS
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_quad : require
#endif
#ifndef SB_MOON
#define SB_MOONLESS /* the day's kernel; SB_MOON the night's (frame.glsl's moon_lights) */
#endif
#include "view_gpu.h"
#include "view.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y, local_size_z_id = SB_VIEW_CONSTANT_BAND_LANES) in;
layout(set = 0, binding = SB_VIEW_BINDING_AERIAL_OUT, rgba16f) uniform writeonly image3D inscatter_out;
layout(set = 0, binding = SB_VIEW_BINDING_AERIAL_T_OUT, rgba16f) uniform writeonly image3D transmittance_out;

#if defined(SB_AERIAL_QUADS) && SB_SPECTRAL_BANDS != 4
#error "a quad holds four bands"
#endif
#ifndef SB_AERIAL_QUADS
/* a slice's bands, each column's: its light as Rec.709 (band_to_rgb), the
 * moon's, and its transmittance */
#define SB_AERIAL_COLUMNS (SB_WORKGROUP_X * SB_WORKGROUP_Y)
shared vec3 band_light[SB_SPECTRAL_BANDS][SB_AERIAL_COLUMNS];
shared vec3 band_moon[SB_SPECTRAL_BANDS][SB_AERIAL_COLUMNS];
shared vec3 band_transmittance[SB_SPECTRAL_BANDS][SB_AERIAL_COLUMNS];
#endif

void main()
{
    /* the invocation's column of the workgroup's and its band: bands
     * vary fastest, so that with quads a column's bands are one quad */
#ifdef SB_AERIAL_QUADS
    uint slot = gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID;
#else
    uint slot = gl_LocalInvocationIndex;
#endif
    uint lanes = gl_WorkGroupSize.z, local = slot / lanes;
    int b = int(slot % lanes);
    uvec2 column = gl_WorkGroupID.xy * uvec2(SB_WORKGROUP_X, SB_WORKGROUP_Y) +
                   uvec2(local % uint(SB_WORKGROUP_X), local / uint(SB_WORKGROUP_X));
    /* no return before the bands meet: a column past the volume marches
     * and does not store */
    bool inside = column.x < SB_AERIAL_SIZE && column.y < SB_AERIAL_SIZE;
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
    atm_band = SB_VIEW_BANDS ? 1 + b : 0;
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
        vec3 sun = atm.solar_irradiance.rgb, moon = sun * frame.moon_light.rgb, L_moon = vec3(0.0);
        integrate_segment(ri, h, mu, mu_s, nu, t0, t1, ms);
        vec3 L = sun * (ri.sun_rayleigh * p_r + ri.sun_mie * p_m) + ri.ms_rayleigh + ri.ms_mie;
        if (!ms)
            L += orders_between(eye, h, mu, mu_s, nu, t1, exp(-ri.tau));
        for (int i = 0; i < moon_lights(); i++) {
            integrate_segment(rm, h, mu, mu_m, nu_m, t0, t1, ms);
            if (SB_VIEW_BANDS) { /* the moon's colour on the bands' sum */
                vec3 Lm = sun * (rm.sun_rayleigh * q_r + rm.sun_mie * q_m) + rm.ms_rayleigh + rm.ms_mie;
                if (!ms)
                    Lm += orders_between(eye_m, h, mu, mu_m, nu_m, t1, exp(-rm.tau));
                L_moon += band_to_rgb(b) * Lm;
                continue;
            }
            L += moon * (rm.sun_rayleigh * q_r + rm.sun_mie * q_m) +
                 frame.moon_light.rgb * (rm.ms_rayleigh + rm.ms_mie);
            if (!ms)
                L += frame.moon_light.rgb * orders_between(eye_m, h, mu, mu_m, nu_m, t1, exp(-rm.tau));
        }
        vec3 T = exp(-ri.tau);
        t0 = t1;
        if (SB_VIEW_BANDS) {
            vec3 light = band_to_rgb(b) * L, sum = vec3(0.0), sum_moon = vec3(0.0), band_t[SB_SPECTRAL_BANDS];
#ifdef SB_AERIAL_QUADS
            /* a constant id each, as quads require (four bands: config.h) */
            sum = subgroupQuadBroadcast(light, 0) + subgroupQuadBroadcast(light, 1) +
                  subgroupQuadBroadcast(light, 2) + subgroupQuadBroadcast(light, 3);
            sum_moon = subgroupQuadBroadcast(L_moon, 0) + subgroupQuadBroadcast(L_moon, 1) +
                       subgroupQuadBroadcast(L_moon, 2) + subgroupQuadBroadcast(L_moon, 3);
            band_t[0] = subgroupQuadBroadcast(T, 0);
            band_t[1] = subgroupQuadBroadcast(T, 1);
            band_t[2] = subgroupQuadBroadcast(T, 2);
            band_t[3] = subgroupQuadBroadcast(T, 3);
#else
            band_light[b][local] = light;
            band_moon[b][local] = L_moon;
            band_transmittance[b][local] = T;
            barrier();
            for (int c = 0; c < SB_SPECTRAL_BANDS; c++) {
                sum += band_light[c][local];
                sum_moon += band_moon[c][local];
                band_t[c] = band_transmittance[c][local];
            }
            barrier(); /* the next slice overwrites them */
#endif
            sum += frame.moon_light.rgb * sum_moon;
            if (b == 0 && inside) {
                imageStore(inscatter_out, ivec3(column, k), vec4(fp16_safe(sum * frame.aerial.y), 1.0));
                imageStore(transmittance_out, ivec3(column, k), vec4(bands_transmittance_rgb(band_t), 1.0));
            }
        } else if (inside) {
            imageStore(inscatter_out, ivec3(column, k), vec4(fp16_safe(L * frame.aerial.y), 1.0));
            imageStore(transmittance_out, ivec3(column, k), vec4(T, 1.0));
        }
    }
}
