#version 450
/* The clouds along one pixel of each clouds.trace.z-pixel block (this
 * frame's, clouds.trace.w): a march through the layer's part of the view
 * ray (cloud_segment), ended by the scene's depth and clouds.march.z. Steps
 * grow linearly from clouds.march.w so that at most clouds.march.x cover
 * the segment; each is read at one point, offset by interleaved gradient
 * noise (Jimenez 2014) that moves every frame; each integrates its light
 * with the extinction held over it (Hillaire 2015): T S (1 - e^(-sigma dt)).
 * Written: in-scattering and transmittance, with the aerial perspective to
 * the clouds' transmittance-weighted distance folded in (the air before the
 * clouds scatters AP_S (1 - T) over what they hide: AP_T S + AP_S (1 - T)),
 * and that distance, for reprojection. */
#extension GL_GOOGLE_include_directive : require
#ifndef SB_MOON
#define SB_MOONLESS /* the day's kernel; SB_MOON the night's (frame.glsl's moon_lights) */
#endif
#include "view_gpu.h"
#include "view.glsl"
#include "aerial.glsl"
#include "cloud_layer.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_DEPTH) uniform sampler2D scene_depth;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_TRACE_OUT, rgba16f) uniform writeonly image2D trace_out;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_DEPTH_OUT, r32f) uniform writeonly image2D depth_out;

#define NO_CLOUD_M 1e5 /* the distance kept where the ray meets no cloud */

void main()
{
    uvec2 id = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(id, clouds.trace.xy)))
        return;
    uint s = clouds.trace.z;
    ivec2 pixel = min(ivec2(id * s + uvec2(clouds.trace.w % s, clouds.trace.w / s)), ivec2(frame.size.xy) - 1);
    vec2 uv = (vec2(pixel) + 0.5) / vec2(frame.size.xy);
    vec3 d = view_ray(uv);
    float depth = texelFetch(scene_depth, pixel, 0).r;
    float scene_m = 1e30;
    if (depth > 0.0) {
        vec4 at = frame.inv_view_proj * vec4(uv * 2.0 - 1.0, depth, 1.0);
        scene_m = length(at.xyz / at.w);
    }

    vec3 S = vec3(0.0);
    float T = 1.0, weighted_m = 0.0, weight = 0.0;
    float t0, t1;
    if (cloud_segment(d, t0, t1)) {
        t1 = min(min(t1, t0 + clouds.march.z), scene_m);
        float length_m = t1 - t0;
        int n_max = int(clouds.march.x);
        float first = clouds.march.w;
        int n = length_m > 0.0 ? int(min(ceil(length_m / first), float(n_max))) : 0;
        /* n steps of first + i grow, summing to the segment's length. */
        float grow = 0.0;
        if (n < n_max)
            first = length_m / float(max(n, 1));
        else
            grow = 2.0 * (length_m - float(n) * first) / (float(n) * float(n - 1));
        float jitter = fract(interleaved_noise(vec2(pixel)) + clouds.temporal.x);
        float h_c = frame.camera_km.w, mu = dot(normalize(frame.camera_km.xyz), d);
        vec3 l = key_direction(), key = atm.solar_irradiance.rgb * key_color(); /* the frame's, once */
        float nu = dot(d, l);
        int light_steps = int(clouds.march.y);
        float t = t0;
        for (int i = 0; i < n; i++) {
            float dt = first + grow * float(i);
            float at = t + jitter * dt;
            t += dt;
            float h_km = altitude_along(h_c, mu, at * 1e-3);
            vec3 q = vec3(frame.camera_m.x + d.x * at, h_km * 1e3, frame.camera_m.z + d.z * at);
            float density = cloud_density(q, true);
            if (density <= 0.0)
                continue;
            vec3 up = normalize(planet_position(d * at));
            float f = (q.y - clouds.layer.x) * clouds.layer.z;
            vec3 light = cloud_light(q, up, l, key, h_km, f, nu, light_steps, jitter);
            float absorbed = T * (1.0 - exp(-density * clouds.layer.w * dt));
            S += light * absorbed;
            weighted_m += absorbed * at;
            weight += absorbed;
            T -= absorbed;
            if (T < 1e-3)
                break;
        }
    }
    float distance_m = weight > 0.0 ? weighted_m / weight : NO_CLOUD_M;
    bool raw = frame.size.w == SB_DEBUG_CLOUDS || frame.size.w == SB_DEBUG_CLOUD_TRANSMITTANCE;
    if (!raw && T < 1.0) {
        vec3 inscatter, transmittance;
        aerial_perspective(uv, d * distance_m, inscatter, transmittance);
        S = S * transmittance + inscatter * (1.0 - T);
    }
    imageStore(trace_out, ivec2(id), vec4(fp16_safe(S), T));
    imageStore(depth_out, ivec2(id), vec4(distance_m));
}
