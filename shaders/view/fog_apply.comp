#version 450
/* The froxel fog applied to the frame, scene and sky: the integrated volume
 * read at the pixel's distance (trilinear; before the end of the first
 * slice, scaled toward nothing at the camera), then beyond the volume's far
 * end the height fog in closed form, its optical depth
 * sigma(y_far) (1 - e^(-t mu / H)) H / mu along the pixel's ray, lit like
 * the volume's last slice but without the cascades, noise or boxes (the
 * clouds' shadow included).
 * colour = colour * T + S. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"
#define SB_FOG_PROBES
#include "probes.glsl"
#include "fog.glsl"
#include "cloud_layer.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_DEPTH) uniform sampler2D scene_depth;
layout(set = 0, binding = SB_VIEW_BINDING_FROXEL) uniform sampler3D froxels;
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform image2D hdr;

#define SKY_DISTANCE_M 1e5 /* how far the tail runs for the sky */

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec2 uv = (vec2(pixel) + 0.5) / vec2(frame.size.xy);
    float depth = texelFetch(scene_depth, pixel, 0).r;
    vec4 point = frame.inv_view_proj * vec4(uv * 2.0 - 1.0, depth > 0.0 ? depth : 0.5, 1.0);
    vec3 offset = point.xyz / point.w;
    vec3 d = normalize(offset);
    float distance = depth > 0.0 ? length(offset) : SKY_DISTANCE_M;
    float far = fog.slices.x, n = float(fog.grid.z);

    float w = froxel_w(min(distance, far));
    vec4 v = textureLod(froxels, vec3(uv, max(w - 0.5 / n, 0.5 / n)), 0.0);
    float first = w * n; /* < 1 before the end of the first slice */
    vec3 inscatter = v.rgb * min(first, 1.0);
    float transmittance = mix(1.0, v.a, min(first, 1.0));

    if (distance > far && fog.jitter.w > 0.0) {
        vec3 p_far = frame.camera_m.xyz + d * far;
        float sigma = height_fog_extinction(p_far.y);
        float x = (distance - far) * d.y * fog.medium.z;
        float tau = abs(x) > 1e-4 ? sigma * (1.0 - exp(min(-x, 80.0))) / (d.y * fog.medium.z)
                                  : sigma * (distance - far);
        vec3 sun, ambient;
        fog_light(d * far, p_far, sun, ambient);
        float clouds_t = cloud_sun_transmittance(p_far);
        vec3 source =
            fog.albedo.rgb * (sun * (phase_hg(fog.medium.w, dot(d, key_direction())) * clouds_t) + ambient);
        inscatter += transmittance * source * (1.0 - exp(-tau));
        transmittance *= exp(-tau);
    }

    vec3 colour = imageLoad(hdr, pixel).rgb;
    if (frame.size.w == SB_DEBUG_FOG)
        colour = inscatter;
    else if (frame.size.w == SB_DEBUG_FOG_TRANSMITTANCE)
        colour = vec3(transmittance * frame.aerial.y); /* read back divided by the scale */
    else if (frame.size.w == SB_DEBUG_NONE || frame.size.w == SB_DEBUG_ENV_SPECULAR)
        colour = colour * transmittance + inscatter;
    imageStore(hdr, pixel, vec4(fp16_safe(colour), 1.0));
}
