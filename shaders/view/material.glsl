/* A world point's material where its textures (vulkan/texels.h, the
 * world's images as the mesh import decoded them) change it: glTF's base
 * colour (times the vertex's albedo), metallic-roughness (roughness times
 * G, metallic times B) and tangent-space normal map (+y up the image: the
 * bitangent is cross(n, t) times the handedness); and what it emits (the
 * emissive factor times its texture). Each image read at the level of the
 * pixel's footprint, given in texture-coordinate units (the raster's from
 * the derivatives, the traced path's from its ray cone). */
#ifndef SB_MATERIAL_GLSL
#define SB_MATERIAL_GLSL

#include "view_gpu.h"

#define TEXELS_BINDING_RECORDS SB_VIEW_BINDING_TEXTURES
#define TEXELS_BINDING_DATA SB_VIEW_BINDING_TEXELS
#include "texels.glsl"

layout(std430, set = 0, binding = SB_VIEW_BINDING_EMISSIVE) readonly buffer EmissiveBuffer {
    sb_emissive_gpu emissive_records[];
};

/* The level of image `image` where the footprint spans `footprint_uv`. */
float material_lod(uint image, float footprint_uv)
{
    vec2 size = texels_size(image);
    return log2(max(footprint_uv * sqrt(size.x * size.y), 1e-20));
}

/* images: the base colour's and the metallic-roughness's texture + 1 (0:
 * none); tangent: xyz along u, w +-(the normal map's texture + 1). n is
 * the surface's unit normal. */
void material_textures(vec2 uv, float footprint_uv, vec2 images, vec4 tangent, inout vec3 albedo,
                       inout vec2 metallic_roughness, inout vec3 n)
{
    uint base = uint(images.x + 0.5), mr = uint(images.y + 0.5), normal = uint(abs(tangent.w) + 0.5);
    if (base != 0u)
        albedo *= texels_sample(base - 1u, uv, material_lod(base - 1u, footprint_uv)).rgb;
    if (mr != 0u) {
        vec4 t = texels_sample(mr - 1u, uv, material_lod(mr - 1u, footprint_uv));
        metallic_roughness *= t.bg;
    }
    if (normal != 0u) {
        vec3 m = texels_sample(normal - 1u, uv, material_lod(normal - 1u, footprint_uv)).xyz * 2.0 - 1.0;
        vec3 t = tangent.xyz - n * dot(n, tangent.xyz);
        if (dot(t, t) > 1e-12) {
            t = normalize(t);
            vec3 b = cross(n, t) * (tangent.w < 0.0 ? -1.0 : 1.0);
            vec3 bent = t * m.x + b * m.y + n * m.z;
            if (dot(bent, bent) > 1e-12)
                n = normalize(bent);
        }
    }
}

/* The radiance a point emits: `record` is its vertex's albedo.w (the
 * emission's record + 1, 0: none). */
vec3 material_emitted(float record, vec2 uv, float footprint_uv)
{
    uint e = uint(record + 0.5);
    if (e == 0u)
        return vec3(0.0);
    vec4 r = emissive_records[e - 1u].radiance;
    uint image = uint(r.w + 0.5);
    vec3 emitted = r.rgb;
    if (image != 0u)
        emitted *= texels_sample(image - 1u, uv, material_lod(image - 1u, footprint_uv)).rgb;
    return emitted;
}

#endif
