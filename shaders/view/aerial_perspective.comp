#version 450
/* The aerial-perspective volume (Hillaire 2020, section 5.4): for 32 x 32
 * screen columns, the radiance scattered into the view ray and the
 * transmittance along it, from the camera to 32 distances, slice k (texel
 * centre w = (k + 0.5) / 32) at d = far * w^2 so slices crowd near the
 * camera. One invocation marches a column, each slice's segment by
 * Gauss-Legendre 4 (integrate_segment), so the slices share one integral.
 * The planet's shadow is included; shadows of the world are not. */
#extension GL_GOOGLE_include_directive : require
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
     * pass integrates per fragment. Each light in the sky's march adds its
     * in-scattering to the slices'. */
    vec3 L[SB_AERIAL_SIZE];
    for (int i = 0; i < sky_light_count(); i++) {
        vec3 l = light_direction(i), color = atm.solar_irradiance.rgb * light_color(i);
        float mu_s = dot(p, l) / r, nu = dot(d, l);
        float p_r = phase_rayleigh(nu), p_m = phase_mie(nu);
        vec3 ms_color = light_color(i);
        RayIntegrals ri = ray_integrals_begin();
        float t0 = 0.0;
        for (int k = 0; k < SB_AERIAL_SIZE; k++) {
            float w = (float(k) + 0.5) / float(SB_AERIAL_SIZE);
            float t1 = frame.aerial.x * w * w;
            integrate_segment(ri, h, mu, mu_s, nu, t0, t1, true);
            t0 = t1;
            vec3 add = color * (ri.sun_rayleigh * p_r + ri.sun_mie * p_m) + ms_color * (ri.ms_rayleigh + ri.ms_mie);
            L[k] = i == 0 ? add : L[k] + add;
            if (i == 0)
                imageStore(transmittance_out, ivec3(column, k), vec4(exp(-ri.tau), 1.0));
        }
    }
    for (int k = 0; k < SB_AERIAL_SIZE; k++)
        imageStore(inscatter_out, ivec3(column, k), vec4(fp16_safe(L[k] * frame.aerial.y), 1.0));
}
