/*
 * The froxel fog's medium, mapping and light, shared by its passes
 * (docs/fog.md). Lengths in metres, world y up; radiance scaled like the
 * frame (frame.aerial.y).
 * - Medium: exponential height fog, extinction sigma_0 e^(-(y - base) / H)
 *   (the exponent at most 20: far below the base the fog stops thickening), thinned by the baked noise
 *   as mix(1, noise, amount), plus boxes whose extinction ramps up over their
 *   edge. Extinction is grey; scattering is albedo times it.
 * - Light: the sun through the atmosphere's transmittance LUT at the
 *   point's altitude and through the height fog above it (its optical depth
 *   toward the sun in closed form, sigma(y) H / mu_s; noise and boxes do not
 *   shade), times a visibility the caller gives (the cascades), with a
 *   Henyey-Greenstein phase; and the ambient: the irradiance from above and
 *   from below (the sky-visibility probes where they cover the point, else
 *   the sky's and the ground's irradiance on open ground) seen as uniform
 *   radiance over each hemisphere, isotropically scattered: (E_up + E_down) / 2pi.
 */
#ifndef SB_FOG_GLSL
#define SB_FOG_GLSL

#include "fog_gpu.h"
#include "view.glsl" /* before phase.glsl: its atmosphere.glsl is skyview's */
#include "phase.glsl"
#include "view_gpu.h"

layout(std430, set = 0, binding = SB_VIEW_BINDING_FOG) readonly buffer FogBuffer {
    sb_fog_gpu fog;
};
layout(set = 0, binding = SB_VIEW_BINDING_FOG_NOISE) uniform sampler3D fog_noise;

/* Distance of slice coordinate w (0 at the camera, 1 at the far end) and back. */
float froxel_distance(float w)
{
    return fog.slices.y * (exp2(w * fog.slices.z) - 1.0);
}

float froxel_w(float d)
{
    return log2(1.0 + d / fog.slices.y) / fog.slices.z;
}

/* The view ray through froxel column xy (continuous: cell centres at + 0.5). */
vec3 froxel_ray(vec2 xy)
{
    return view_ray(xy / vec2(fog.grid.xy));
}

/* The height fog's extinction at world height y. */
float height_fog_extinction(float y)
{
    return fog.medium.x * exp(min(-(y - fog.medium.y) * fog.medium.z, 20.0));
}

/* Extinction (1/m) at world point p. */
float fog_extinction(vec3 p)
{
    float sigma = height_fog_extinction(p.y);
    if (fog.albedo.w > 0.0) {
        float n = textureLod(fog_noise, (p + fog.noise.xyz) * fog.noise.w, 0.0).r;
        sigma *= mix(1.0, clamp(n, 0.0, 1.0), fog.albedo.w);
    }
    for (uint i = 0u; i < fog.grid.w; i++) {
        vec3 lo = fog.volume_min[i].xyz, hi = fog.volume_max[i].xyz;
        vec3 inside = min(p - lo, hi - p); /* distance inside each pair of faces */
        float depth = min(inside.x, min(inside.y, inside.z));
        if (depth > 0.0)
            sigma += fog.volume_min[i].w * clamp(depth / max(fog.volume_max[i].w, 1e-6), 0.0, 1.0);
    }
    return sigma;
}

/* The key light's (the sun's, or the moon's at night) reaching world point p (offset from the camera), before
 * visibility and phase, and the ambient in-scattering per unit scattering:
 * both times the frame's radiance scale. */
void fog_light(vec3 offset, vec3 p, out vec3 sun, out vec3 ambient)
{
    vec3 planet = planet_position(offset);
    float r = length(planet);
    vec3 up = planet / r;
    float h = max(r - ground_radius(), 0.0);
    float mu_s = dot(up, key_direction());
    float tau_sun = height_fog_extinction(p.y) / (fog.medium.z * max(mu_s, 1e-4)); /* H >= 1 m: z > 0 */
    sun = atm.solar_irradiance.rgb * key_color() * sun_transmittance_rgb(h, mu_s) * (exp(-tau_sun) * frame.aerial.y);
    vec3 e_up, e_down;
    sky_irradiance(up, e_up, e_down);
#ifdef SB_FOG_PROBES
    probe_sample light;
    float coverage;
    probe_lookup(p, vec3(0.0, 1.0, 0.0), vec3(0.0, -1.0, 0.0), light, coverage);
    e_up = mix(e_up, light.e_n, coverage);
    e_down = mix(e_down, light.e_r, coverage);
#endif
    ambient = (e_up + e_down) * (frame.aerial.y / (2.0 * PI));
}

#endif
