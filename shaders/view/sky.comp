#version 450
/* The sky behind the world (where the scene left depth 0): the sky-view LUT
 * inside the atmosphere (a layer a light in the sky), the same integral per
 * pixel from the top of the atmosphere above it (the LUT's rows cannot hold
 * a planet seen from space), the planet's ground below the horizon, and the
 * sun's and the moon's disks where the planet does not hide them, seen
 * through the transmittance toward them. Built twice:
 * for a camera inside the atmosphere, and with SB_SKY_FROM_SPACE for one
 * above it; the renderer dispatches the one the frame needs, since llvmpipe
 * runs an untaken branch's code too (a quarter of the pass's time there). */
#extension GL_GOOGLE_include_directive : require
#ifndef SB_MOON
#define SB_MOONLESS /* the day's kernel; SB_MOON the night's (frame.glsl's moon_lights) */
#endif
#include "view_gpu.h"
#include "view.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_SKY_VIEW) uniform sampler2DArray sky_view;
layout(set = 0, binding = SB_VIEW_BINDING_DEPTH) uniform sampler2D scene_depth;
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform image2D hdr;

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    if (texelFetch(scene_depth, pixel, 0).r != 0.0)
        return;
    vec3 d = view_ray((vec2(pixel) + 0.5) / vec2(frame.size.xy));
    vec3 p = frame.camera_km.xyz;
    float nu = clamp(dot(d, frame.sun_direction.xyz), -1.0, 1.0);

    vec3 L = vec3(0.0);
    vec3 view_t = vec3(0.0); /* transmittance along the view to space, 0 when the planet hides it */
#ifndef SB_SKY_FROM_SPACE
    {
        vec3 up = normalize(p);
        float h = clamp(frame.camera_km.w, 0.0, atmosphere_thickness()); /* as the LUT was made */
        float mu = clamp(dot(up, d), -1.0, 1.0);
        L = textureLod(sky_view, vec3(sky_view_uv_toward(d, frame.sun_direction.xyz), 0.0), 0.0).rgb;
        for (int i = 0; i < moon_lights(); i++)
            L += textureLod(sky_view, vec3(sky_view_uv_toward(d, frame.moon_direction.xyz), 1.0), 0.0).rgb;
        if (!ray_hits_ground(h, mu))
            view_t = transmittance_rgb(h, mu);
    }
#else
    {
        float entry = atmosphere_entry(p, d);
        if (entry >= 0.0) {
            vec3 p0 = p + d * entry;
            float r0 = length(p0);
            float h0 = clamp(r0 - ground_radius(), 0.0, atmosphere_thickness());
            float mu = clamp(dot(p0, d) / r0, -1.0, 1.0);
            for (int i = 0; i < sky_light_count(); i++) {
                vec3 l = light_direction(i);
                float mu_s = clamp(dot(p0, l) / r0, -1.0, 1.0);
                L += sky_radiance_rgb(h0, mu, mu_s, clamp(dot(d, l), -1.0, 1.0)) * light_color(i) * frame.aerial.y;
            }
            if (!ray_hits_ground(h0, mu))
                view_t = transmittance_rgb(h0, mu);
        } else {
            view_t = vec3(1.0);
        }
    }
#endif
    vec3 disks = sun_disk(nu);
    for (int i = 0; i < int(frame.moon_direction.w > 0.0); i++)
        disks += moon_disk(d);
    L += disks * view_t * frame.aerial.y;
    imageStore(hdr, pixel, vec4(fp16_safe(L), 1.0));
}
