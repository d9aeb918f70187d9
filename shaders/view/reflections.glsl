/* skyview's reflection probes (reflections_gpu.h, sb_reflections_gpu): the pack's
 * prefiltered cubes read from a storage buffer (bilinear within a face,
 * linear between mips; the prefilter made the data seamless, and a lookup
 * at a face's edge clamps to it), parallax-corrected against each probe's
 * box (Lagarde and Zanuttini 2012) and blended where boxes overlap, the
 * sky-only cube filling what no box covers; the DFG LUT for the split-sum
 * specular. */
#ifndef SB_REFLECTIONS_GLSL
#define SB_REFLECTIONS_GLSL

#include "reflections_gpu.h"
#include "view_gpu.h"

#include "cube.glsl"

layout(std430, set = 0, binding = SB_VIEW_BINDING_REFLECTIONS) readonly buffer ReflectionBuffer {
    sb_reflections_gpu reflections;
    vec4 reflection_data[];
};
#ifdef REFLECTION_CUBES_WRITABLE
layout(std430, set = 0, binding = SB_VIEW_BINDING_REFLECTION_CUBES) buffer ReflectionCubes {
#else
layout(std430, set = 0, binding = SB_VIEW_BINDING_REFLECTION_CUBES) readonly buffer ReflectionCubes {
#endif
    vec4 cube_texels[];
};

uint reflection_level_offset(uint level)
{
    return reflections.level_offsets[level / 4u][level % 4u];
}

vec3 reflection_fetch(uint cube, vec3 d, uint level)
{
    uint n = max(reflections.info.x >> level, 1u);
    vec3 rgb;
    CUBE_BILINEAR(cube_texels, cube * reflections.level_offsets[3].w + reflection_level_offset(level), n, d, rgb);
    return rgb;
}

/* Radiance prefiltered for perceptual roughness r along d: the mip
 * Filament's mapping puts r at, (levels - 1) r (2 - r). */
vec3 reflection_sample(uint cube, vec3 d, float r)
{
    float top = float(reflections.info.y - 1u);
    float lod = clamp(top * r * (2.0 - r), 0.0, top);
    uint l0 = uint(lod);
    float f = lod - float(l0);
    vec3 a = reflection_fetch(cube, d, l0);
    return f > 0.0 ? a + (reflection_fetch(cube, d, min(l0 + 1u, reflections.info.y - 1u)) - a) * f : a;
}

/* The DFG LUT at (n.v, r), bilinear between texel centres: x the
 * Fresnel-weighted, y the whole directional albedo of GGX. */
vec2 reflection_dfg(float n_dot_v, float r)
{
    vec2 p = clamp(vec2(n_dot_v, r) * float(SB_DFG_SIZE) - 0.5, vec2(0.0), vec2(float(SB_DFG_SIZE - 1)));
    ivec2 i0 = ivec2(p), i1 = min(i0 + 1, ivec2(SB_DFG_SIZE - 1));
    vec2 f = p - vec2(i0);
    uint base = 3u * reflections.info.z;
    vec2 a = reflection_data[base + i0.y * SB_DFG_SIZE + i0.x].xy, b = reflection_data[base + i0.y * SB_DFG_SIZE + i1.x].xy;
    vec2 c = reflection_data[base + i1.y * SB_DFG_SIZE + i0.x].xy, e = reflection_data[base + i1.y * SB_DFG_SIZE + i1.x].xy;
    vec2 top = a + (b - a) * f.x, bottom = c + (e - c) * f.x;
    return top + (bottom - top) * f.y;
}

/* How much probe i (a scene probe, i >= 1) stands for point pos: 1 inside
 * its box, falling to 0 over the last metre (or a quarter of the box's
 * smallest side) to its faces. */
float reflection_weight(uint i, vec3 pos)
{
    vec3 lo = reflection_data[3u * i + 1u].xyz, hi = reflection_data[3u * i + 2u].xyz;
    vec3 inside = min(pos - lo, hi - pos);
    float margin = min(inside.x, min(inside.y, inside.z));
    float fade = min(1.0, 0.25 * min(hi.x - lo.x, min(hi.y - lo.y, hi.z - lo.z)));
    return clamp(margin / fade, 0.0, 1.0);
}

/* The direction probe i's cube holds what the ray from pos along r meets
 * on its box (the box seen from inside). */
vec3 reflection_parallax(uint i, vec3 pos, vec3 r)
{
    vec3 lo = reflection_data[3u * i + 1u].xyz, hi = reflection_data[3u * i + 2u].xyz;
    vec3 inv = 1.0 / r;
    vec3 t_far = max((lo - pos) * inv, (hi - pos) * inv);
    float t = min(t_far.x, min(t_far.y, t_far.z));
    return pos + r * max(t, 0.0) - reflection_data[3u * i].xyz;
}

/* The prefiltered radiance a surface at pos with roughness r sees along
 * the mirror direction refl: the boxes that hold pos, each parallax-
 * corrected, normalised where they overlap, the sky-only cube for the
 * rest, of which only the share sky_seen (specular occlusion) reaches the
 * sky; *hidden is the weight left to what hides the sky there (the
 * caller's radiance of it). */
vec3 reflection_radiance(vec3 pos, vec3 refl, float r, float sky_seen, out float hidden)
{
    hidden = 0.0;
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (uint i = 1u; i < reflections.info.z; i++) {
        float w = reflection_weight(i, pos);
        if (w <= 0.0)
            continue;
        sum += w * reflection_sample(i, reflection_parallax(i, pos, refl), r);
        weight += w;
    }
    if (weight > 1.0)
        return sum / weight;
    hidden = (1.0 - weight) * (1.0 - sky_seen);
    return sum + (1.0 - weight) * sky_seen * reflection_sample(0u, refl, r);
}

#endif
