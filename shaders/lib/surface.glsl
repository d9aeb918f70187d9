// What a ray sees of a surface it hits (baker/surfaces.h): the material's
// albedo times its base-colour texture at the hit, filtered at the mip the
// ray's footprint asks for (ray cones: Akenine-Möller et al., "Texture
// Level of Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems
// 2019, ch. 20). A kernel that includes this defines SURFACE_BINDING
// (four bindings from it: materials, uvs, textures, texels, config.h's
// SB_SURFACE_*) and includes bvh.glsl with BVH_HIT_SLOT first.
#ifndef SB_SURFACE_GLSL
#define SB_SURFACE_GLSL

#include "config.h"

struct SurfaceMaterial {
    vec3 albedo;       // linear
    uint base_texture; // its base-colour texture + 1; 0: none
};
layout(std430, binding = SURFACE_BINDING + SB_SURFACE_MATERIALS) readonly buffer SurfaceMaterials {
    SurfaceMaterial surface_materials[];
};
// three (u, v) a triangle, by the triangle's index (bvh_triangles' v0.w)
layout(std430, binding = SURFACE_BINDING + SB_SURFACE_UVS) readonly buffer SurfaceUvs { vec2 surface_uvs[]; };
#define TEXELS_BINDING_RECORDS (SURFACE_BINDING + SB_SURFACE_TEXTURES)
#define TEXELS_BINDING_DATA (SURFACE_BINDING + SB_SURFACE_TEXELS)
#include "texels.glsl"

// The albedo where `hit` (traced with BVH_HIT_SLOT) met its triangle:
// `width_m` the ray cone's width there, `cosine` |n.d| at the hit. The
// cone's footprint on the surface is width / cosine long and width wide;
// the texture is filtered over a square of its area (width / sqrt(cosine)
// a side): the mean albedo over the patch the ray stands for, which an
// estimator summing rays needs (a ray cone's width / cosine, right for an
// image, would blur grazing hits over twice the patch and more).
vec3 surface_albedo(BvhHit hit, float width_m, float cosine)
{
    vec4 v0 = bvh_triangles[3u * hit.slot], e1 = bvh_triangles[3u * hit.slot + 1u];
    SurfaceMaterial m = surface_materials[floatBitsToUint(e1.w)];
    if (m.base_texture == 0u)
        return m.albedo;
    uint triangle = floatBitsToUint(v0.w);
    vec2 a = surface_uvs[3u * triangle], b = surface_uvs[3u * triangle + 1u], c = surface_uvs[3u * triangle + 2u];
    vec2 uv = a * (1.0 - hit.uv.x - hit.uv.y) + b * hit.uv.x + c * hit.uv.y;
    uint image = m.base_texture - 1u;
    // the level: texels a triangle area over its area (both of the mesh's
    // space: an instance's scale is left out), then the cone's footprint
    vec3 e2 = bvh_triangles[3u * hit.slot + 2u].xyz;
    vec2 du = b - a, dv = c - a, size = texels_size(image);
    float texels = abs(du.x * dv.y - du.y * dv.x) * size.x * size.y;
    float area = length(cross(e1.xyz, e2));
    float lod = 0.5 * log2(max(texels, 1e-20) / max(area, 1e-20)) + log2(max(width_m, 1e-20) / sqrt(max(cosine, 1e-4)));
    return m.albedo * texels_sample(image, uv, lod).rgb;
}

#endif
