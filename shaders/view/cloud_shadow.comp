#version 450
/* The clouds' shadow map: for the ground point under each texel (a square
 * of clouds.shadow.z metres about clouds.shadow.xy, world y = 0 on the
 * curved planet), the optical depth toward the sun through the whole layer
 * (midpoint rule, clouds.shadow.w pieces over the crossing, at most
 * SB_CLOUD_SHADOW_REACH_M long). cloud_sun_transmittance reads it. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"
#include "cloud_layer.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_SHADOW_OUT, rgba16f) uniform writeonly image2D shadow_out;

void main()
{
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(shadow_out);
    if (any(greaterThanEqual(texel, size)))
        return;
    vec2 g = clouds.shadow.xy + ((vec2(texel) + 0.5) / vec2(size) - 0.5) * clouds.shadow.z;
    vec3 offset = vec3(g.x, 0.0, g.y) - frame.camera_m.xyz;
    vec3 planet = planet_position(offset);
    float r = length(planet);
    float h_km = max(r - ground_radius(), 0.0);
    float mu_s = dot(planet / r, key_direction());
    float tau = 0.0;
    if (clouds.erosion.z != 0.0 && !ray_hits_ground(h_km, mu_s)) {
        float enter = max(cloud_sphere_hits(h_km, mu_s, clouds.layer.x * 1e-3).y, 0.0) * 1e3;
        float leave = cloud_sphere_hits(h_km, mu_s, clouds.layer.y * 1e-3).y * 1e3;
        leave = min(leave, enter + SB_CLOUD_SHADOW_REACH_M);
        int steps = int(clouds.shadow.w);
        float piece = max(leave - enter, 0.0) / float(steps);
        vec3 l = key_direction();
        for (int i = 0; i < steps; i++) {
            float s = enter + (float(i) + 0.5) * piece;
            vec3 q = vec3(g.x + l.x * s, altitude_along(h_km, mu_s, s * 1e-3) * 1e3, g.y + l.z * s);
            tau += cloud_density(q, true) * piece;
        }
        tau *= clouds.layer.w;
    }
    imageStore(shadow_out, texel, vec4(min(tau, 65000.0), 0.0, 0.0, 1.0));
}
