#version 450
/* The world rasterised: scene_shading.glsl lights each fragment, with the
 * key light's visibility from the cascaded shadow maps (normal offset,
 * penumbrae by the light's disk or a 3x3 comparison PCF, a blend band
 * between cascades: shadows.glsl). */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "scene_shading.glsl"
#define SB_SOFT_SHADOWS
#include "shadows.glsl"
#include "material.glsl"

layout(location = 0) in vec3 in_offset;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec3 in_albedo;
layout(location = 3) in vec2 in_metallic_roughness;
layout(location = 4) in vec2 in_uv;
layout(location = 5) flat in vec2 in_images;
layout(location = 6) in vec3 in_tangent;
layout(location = 7) flat in float in_normal_map;
layout(location = 8) flat in float in_emission;
layout(location = 0) out vec4 out_color;
#ifdef SB_KEY_TARGET
layout(location = 1) out vec4 out_key; /* the key light's direct share, for the contact shadows */
#endif

void main()
{
    vec3 n = normalize(in_normal);
    /* the footprint from the derivatives, taken where every fragment of the quad runs */
    float footprint = max(length(dFdx(in_uv)), length(dFdy(in_uv)));
    vec3 albedo = in_albedo;
    vec2 metallic_roughness = in_metallic_roughness;
    vec3 shading_n = n;
    if (SB_SCENE_TEXTURES && (in_images != vec2(0.0) || in_normal_map != 0.0))
        material_textures(in_uv, footprint, in_images, vec4(in_tangent, in_normal_map), albedo, metallic_roughness,
                          shading_n);
    vec3 emitted = SB_SCENE_EMISSION ? material_emitted(in_emission, in_uv, footprint) : vec3(0.0);
    vec3 key_part;
    out_color = scene_shade(in_offset, shading_n, n, albedo, metallic_roughness, emitted,
                            gl_FragCoord.xy / vec2(frame.size.xy), sun_visibility(in_offset, n, true), key_part);
#ifdef SB_KEY_TARGET
    out_key = vec4(key_part, 0.0);
#endif
}
