#version 450
/* One froxel's medium and light (fog.glsl) at this frame's jittered sample
 * in it, blended with the last frame's value reprojected to the froxel's
 * centre (Hillaire 2015; Wronski 2014): scattering (rgb) and extinction (a).
 * The history is rejected where the centre was outside the last frame's
 * volume and when the renderer clears its weight (a cut, a moved sun, the
 * first frame). */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"
#define SB_FOG_PROBES
#include "probes.glsl"
#include "fog.glsl"
#include "shadows.glsl"
#include "cloud_layer.glsl"

layout(local_size_x = SB_FOG_GROUP, local_size_y = SB_FOG_GROUP, local_size_z = SB_FOG_GROUP) in;
layout(set = 0, binding = SB_VIEW_BINDING_FROXEL_LIGHT_OUT, rgba16f) uniform writeonly image3D light_out;
layout(set = 0, binding = SB_VIEW_BINDING_FROXEL_HISTORY) uniform sampler3D history;

vec4 froxel_light(vec3 cell)
{
    vec3 d = froxel_ray(cell.xy);
    vec3 offset = d * froxel_distance(cell.z / float(fog.grid.z));
    vec3 p = offset + frame.camera_m.xyz;
    float sigma = fog_extinction(p);
    if (sigma <= 0.0)
        return vec4(0.0);
    vec3 sun, ambient;
    fog_light(offset, p, sun, ambient);
    float nu = dot(d, key_direction());
    vec3 light = sun * (phase_hg(fog.medium.w, nu) * sun_visibility(offset, vec3(0.0), false) * cloud_sun_transmittance(p)) + ambient;
    return min(vec4(fog.albedo.rgb * sigma * light, sigma), vec4(65000.0));
}

void main()
{
    uvec3 id = gl_GlobalInvocationID;
    if (any(greaterThanEqual(id, fog.grid.xyz)))
        return;
    vec4 value = froxel_light(vec3(id) + fog.jitter.xyz);
    float weight = fog.slices.w;
    if (weight > 0.0) {
        /* The froxel's centre, where the last frame's volume saw it. */
        vec3 centre = vec3(id) + 0.5;
        vec3 offset = froxel_ray(centre.xy) * froxel_distance(centre.z / float(fog.grid.z));
        vec3 before = offset + fog.camera_motion_m.xyz;
        vec4 clip = fog.previous_view_proj * vec4(before, 1.0);
        vec3 uvw = vec3(clip.xy / clip.w * 0.5 + 0.5, froxel_w(length(before)));
        /* The texel centres of the first and last slices bound what can be
         * reprojected: beyond them the history is an extrapolation. */
        vec3 margin = 0.5 / vec3(fog.grid.xyz);
        if (clip.w > 0.0 && all(greaterThanEqual(uvw, margin)) && all(lessThanEqual(uvw, 1.0 - margin)))
            value = mix(value, textureLod(history, uvw, 0.0) * vec4(vec3(fog.camera_motion_m.w), 1.0), weight);
    }
    imageStore(light_out, ivec3(id), value);
}
