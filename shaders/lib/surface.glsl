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
// (first texel, width | height << 16, levels | wrap u << 8 | wrap v << 10 | srgb << 12, 0) a texture
layout(std430, binding = SURFACE_BINDING + SB_SURFACE_TEXTURES) readonly buffer SurfaceTextures {
    uvec4 surface_textures[];
};
// every texture's levels in turn, level 0 first, rows from the image's top, RGBA8
layout(std430, binding = SURFACE_BINDING + SB_SURFACE_TEXELS) readonly buffer SurfaceTexels { uint surface_texels[]; };

float surface_srgb_to_linear(float c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

// u reduced to the wrap mode's period (coordinates stay small), then to a
// texel index in [0, n)
float surface_wrap_coordinate(float u, uint mode)
{
    if (mode == SB_SURFACE_WRAP_REPEAT)
        return u - floor(u);
    if (mode == SB_SURFACE_WRAP_MIRROR) {
        float m = u - 2.0 * floor(0.5 * u);
        return m <= 1.0 ? m : 2.0 - m;
    }
    return clamp(u, 0.0, 1.0);
}

int surface_wrap_texel(int i, int n, uint mode)
{
    if (mode == SB_SURFACE_WRAP_REPEAT)
        return (i % n + n) % n;
    if (mode == SB_SURFACE_WRAP_MIRROR) {
        int m = (i % (2 * n) + 2 * n) % (2 * n);
        return m < n ? m : 2 * n - 1 - m;
    }
    return clamp(i, 0, n - 1);
}

vec4 surface_texel(uint at, int width, int x, int y, bool srgb)
{
    vec4 c = unpackUnorm4x8(surface_texels[at + uint(y * width + x)]);
    if (srgb)
        c.rgb = vec3(surface_srgb_to_linear(c.r), surface_srgb_to_linear(c.g), surface_srgb_to_linear(c.b));
    return c;
}

// Bilinear at one level (u right, v up from the last row).
vec4 surface_bilinear(uvec4 t, uint level, vec2 uv)
{
    uint wrap_u = (t.z >> 8) & 3u, wrap_v = (t.z >> 10) & 3u;
    bool srgb = ((t.z >> 12) & 1u) != 0u;
    int w = int(t.y & 0xffffu), h = int(t.y >> 16);
    uint at = t.x;
    for (uint l = 0u; l < level; l++) {
        at += uint(w * h);
        w = max(w >> 1, 1);
        h = max(h >> 1, 1);
    }
    float x = surface_wrap_coordinate(uv.x, wrap_u) * float(w) - 0.5;
    float y = (1.0 - surface_wrap_coordinate(uv.y, wrap_v)) * float(h) - 0.5;
    int x0 = int(floor(x)), y0 = int(floor(y));
    vec2 f = vec2(x - float(x0), y - float(y0));
    int xa = surface_wrap_texel(x0, w, wrap_u), xb = surface_wrap_texel(x0 + 1, w, wrap_u);
    int ya = surface_wrap_texel(y0, h, wrap_v), yb = surface_wrap_texel(y0 + 1, h, wrap_v);
    vec4 top = mix(surface_texel(at, w, xa, ya, srgb), surface_texel(at, w, xb, ya, srgb), f.x);
    vec4 bottom = mix(surface_texel(at, w, xa, yb, srgb), surface_texel(at, w, xb, yb, srgb), f.x);
    return mix(top, bottom, f.y);
}

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
    uvec4 t = surface_textures[m.base_texture - 1u];
    // the level: texels a triangle area over its area (both of the mesh's
    // space: an instance's scale is left out), then the cone's footprint
    vec3 e2 = bvh_triangles[3u * hit.slot + 2u].xyz;
    vec2 du = b - a, dv = c - a;
    float texels = abs(du.x * dv.y - du.y * dv.x) * float(t.y & 0xffffu) * float(t.y >> 16);
    float area = length(cross(e1.xyz, e2));
    float lod = 0.5 * log2(max(texels, 1e-20) / max(area, 1e-20)) + log2(max(width_m, 1e-20) / sqrt(max(cosine, 1e-4)));
    float levels = float(t.z & 0xffu);
    lod = clamp(lod, 0.0, levels - 1.0);
    uint l0 = uint(lod);
    vec4 texel = surface_bilinear(t, l0, uv);
    if (float(l0) < lod)
        texel = mix(texel, surface_bilinear(t, min(l0 + 1u, uint(levels) - 1u), uv), lod - float(l0));
    return m.albedo * texel.rgb;
}

#endif
