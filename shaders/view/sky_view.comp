#version 450
/* The sky-view LUT (Hillaire 2020, section 5.3): sky radiance around the
 * camera at its altitude, one ray per texel with the bakes' quadrature
 * (sky_radiance), for the sky pass to read; a layer for each light in the
 * sky (the z of the dispatch), about its direction, in its colour. Above
 * the atmosphere the camera is lowered to its top; the sky pass then
 * integrates per pixel instead. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_SKY_VIEW_OUT, rgba16f) uniform writeonly image2DArray sky_view_out;

void main()
{
    uvec2 texel = gl_GlobalInvocationID.xy;
    int light = int(gl_GlobalInvocationID.z);
    if (texel.x >= SB_SKY_VIEW_WIDTH || texel.y >= SB_SKY_VIEW_HEIGHT)
        return;
    float h = clamp(frame.camera_km.w, 0.0, atmosphere_thickness());
    vec2 uv = (vec2(texel) + 0.5) / vec2(SB_SKY_VIEW_WIDTH, SB_SKY_VIEW_HEIGHT);
    vec2 angles = sky_view_angles(uv, h);
    float mu = cos(angles.y);
    vec3 up = normalize(frame.camera_km.xyz);
    float mu_s = clamp(dot(up, light_direction(light)), -1.0, 1.0);
    float sin_v = sin(angles.y), sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    float nu = clamp(mu * mu_s + sin_v * sin_s * cos(angles.x), -1.0, 1.0);
    vec3 L = sky_radiance_rgb(h, mu, mu_s, nu) * light_color(light) * frame.aerial.y;
    imageStore(sky_view_out, ivec3(texel, light), vec4(fp16_safe(L), 1.0));
}
