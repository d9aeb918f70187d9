#version 450
/* The world rasterised: scene_shading.glsl lights each fragment, with the
 * sun's visibility from the cascaded shadow maps (normal offset, 3x3
 * comparison PCF, a blend band between cascades: shadows.glsl). */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "scene_shading.glsl"
#include "shadows.glsl"

layout(location = 0) in vec3 in_offset;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec3 in_albedo;
layout(location = 3) in vec2 in_metallic_roughness;
layout(location = 0) out vec4 out_color;

void main()
{
    vec3 n = normalize(in_normal);
    out_color = scene_shade(in_offset, n, in_albedo, in_metallic_roughness, gl_FragCoord.xy / vec2(frame.size.xy),
                            sun_visibility(in_offset, n, true));
}
