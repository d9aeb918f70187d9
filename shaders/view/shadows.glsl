/*
 * The key light's visibility (the sun's, or the moon's at night: frame.glsl)
 * through skyview's cascaded shadow maps, for a point
 * `offset` metres from the camera: the cascade by view depth, a normal offset
 * of frame.shadow.y texels along n (0 for points in the air), the depth
 * compare filtered bilinearly by the sampler (zero gradients: compute
 * shaders have none, and the maps have one level), then 3 x 3 taps with pcf (the
 * scene) or one (the fog, whose jitter and history filter it), and a blend
 * band toward the next cascade. 1 beyond the last cascade, and outside the
 * box of a cascade's casters, where the map was neither cleared nor drawn
 * (frame.cascade_rect; runtime/shadows.h).
 *
 * With SB_TRACED_SHADOWS (the traced scene, runtime/scene_trace.c), a
 * shadow ray instead: from the point, lifted off its surface along n,
 * toward the light's centre through the world's BVH, any caster ending it.
 * Exact and hard (no penumbra, no filtering), at every distance.
 */
#ifndef SB_SHADOWS_GLSL
#define SB_SHADOWS_GLSL

#include "view_gpu.h"
#include "frame.glsl"

#ifdef SB_TRACED_SHADOWS
layout(std430, set = 0, binding = SB_VIEW_BINDING_BVH_NODES) readonly buffer BvhNodes { vec4 bvh_nodes[]; };
layout(std430, set = 0, binding = SB_VIEW_BINDING_BVH_TRIANGLES) readonly buffer BvhTriangles { vec4 bvh_triangles[]; };
#define BVH_ANY_HIT_MATERIAL_0_PASSES /* receivers only (a ground) cast no shadow, as in the maps */
#include "bvh.glsl"

/* `pcf` is the raster's: a ray needs no filter. */
float sun_visibility(vec3 offset, vec3 n, bool pcf)
{
    if (frame.shadow.w == 0.0)
        return 1.0;
    vec3 l = key_direction();
    vec3 c = abs(frame.camera_m.xyz), p = offset + frame.camera_m.xyz;
    /* Off the surface, to the side the sun is on, by 1 mm and 4e-6 of the
     * scale of the point's rounding: it was found from the camera at
     * `offset` (a ray's t) and placed in the world (fp32 steps of |p| <=
     * |camera| + |offset|), so the lift stays a fixed fraction of a pixel's
     * footprint however far the camera is. */
    float lift = 1e-3 + 4e-6 * (max(c.x, max(c.y, c.z)) + length(offset));
    vec3 o = p + n * (dot(n, l) < 0.0 ? -lift : lift);
    return bvh_trace(o, l, 0.0, SB_TRACE_FAR_M, true).triangle == SB_BVH_MISS ? 1.0 : 0.0;
}
#else

layout(set = 0, binding = SB_VIEW_BINDING_SHADOW) uniform sampler2DArrayShadow shadow_map;

float cascade_visibility(int c, vec3 offset, vec3 n, bool pcf)
{
    vec3 p = offset + n * (frame.cascade_texel[c] * frame.shadow.y);
    vec4 clip = frame.shadow_view_proj[c] * vec4(p, 1.0);
    vec3 s = clip.xyz / clip.w;
    vec2 uv = s.xy * 0.5 + 0.5;
    vec4 rect = frame.cascade_rect[c];
    if (any(lessThan(uv, max(rect.xy, vec2(0.0)))) || any(greaterThan(uv, min(rect.zw, vec2(1.0)))) || s.z > 1.0)
        return 1.0;
    if (!pcf)
        return textureGrad(shadow_map, vec4(uv, float(c), s.z), vec2(0.0), vec2(0.0));
    /* 3 x 3 bilinear taps a texel apart weigh the 4 x 4 texels from
     * base - 1 by (1 - f, 1, 1, f) / 3 in each axis (f: the point's
     * fraction past texel base). Two bilinear taps give the same weights,
     * one on the first pair (2 - f of them, 1 / (2 - f) of the way across)
     * and one on the last (1 + f, f / (1 + f) across): 2 x 2 taps instead of
     * 3 x 3 (Castano 2013), the same filter up to the sampler's rounding of
     * its weights. f is rounded to 1/256, a GPU sampler's own precision, so
     * that the four weights and their sum are exact: a region all lit or all
     * shadowed reads exactly 1 or 0. */
    float size = frame.shadow.z;
    vec2 x = uv * size - 0.5, base = floor(x), f = floor((x - base) * 256.0 + 0.5) / 256.0;
    vec2 w0 = 2.0 - f, w1 = 1.0 + f;
    vec2 p0 = (base - 0.5 + 1.0 / w0) / size, p1 = (base + 1.5 + f / w1) / size;
    float sum = w0.x * w0.y * textureGrad(shadow_map, vec4(p0, float(c), s.z), vec2(0.0), vec2(0.0))
              + w1.x * w0.y * textureGrad(shadow_map, vec4(p1.x, p0.y, float(c), s.z), vec2(0.0), vec2(0.0))
              + w0.x * w1.y * textureGrad(shadow_map, vec4(p0.x, p1.y, float(c), s.z), vec2(0.0), vec2(0.0))
              + w1.x * w1.y * textureGrad(shadow_map, vec4(p1, float(c), s.z), vec2(0.0), vec2(0.0));
    return sum / 9.0;
}

float sun_visibility(vec3 offset, vec3 n, bool pcf)
{
    if (frame.shadow.w == 0.0)
        return 1.0;
    float depth = dot(offset, frame.camera_forward.xyz);
    int c = 0;
    while (c < SB_CASCADES && depth > frame.cascade_ends[c])
        c++;
    if (c == SB_CASCADES)
        return 1.0;
    float begin = c == 0 ? 0.0 : frame.cascade_ends[c - 1];
    float band = frame.shadow.x * (frame.cascade_ends[c] - begin);
    float f = band > 0.0 ? (depth - (frame.cascade_ends[c] - band)) / band : 0.0;
    /* In the band, toward the next cascade, or out of the shadows past the
     * last. The next cascade is read in a loop's second turn, not in a
     * branch: llvmpipe runs a branch's code whether or not an invocation
     * takes it, but ends a loop when none of its SIMD group goes on, and
     * few groups meet a band (lavapipe's scene pass 46 -> 41 ms at 640 x 360). */
    float visibility = 1.0, next = 1.0;
    int last = f > 0.0 && c + 1 < SB_CASCADES ? c + 1 : c;
    for (int k = c; k <= last; k++) {
        float v = cascade_visibility(k, offset, n, pcf);
        if (k == c)
            visibility = v;
        else
            next = v;
    }
    if (f > 0.0)
        visibility = mix(visibility, next, f);
    return visibility;
}
#endif /* SB_TRACED_SHADOWS */

#endif
