/*
 * The key light's visibility (the sun's, or the moon's at night: frame.glsl)
 * through skyview's cascaded shadow maps, for a point
 * `offset` metres from the camera: the cascade by view depth, a normal offset
 * of frame.shadow.y texels along n (0 for points in the air), the depth
 * compare filtered bilinearly by the sampler (zero gradients: compute
 * shaders have none, and the maps have one level), then with pcf (the
 * scene) the penumbra of the light's disk where SB_SOFT_SHADOWS asks for it
 * (soft_visibility) or 3 x 3 taps, or one tap (the fog, whose jitter and
 * history filter it), and a blend band toward the next cascade. 1 beyond the
 * last cascade, and outside the box of a cascade's casters (and the
 * penumbra's reach past it), where the map was neither cleared nor drawn
 * (frame.cascade_rect; runtime/shadows.h).
 *
 * With SB_TRACED_SHADOWS (the traced scene, runtime/scene_trace.c), a
 * shadow ray instead: from the point, lifted off its surface along n,
 * toward the light's centre through the world's BVH, any caster ending it,
 * exact at every distance; the scene traces toward points over the light's
 * disk, a new one each frame (disk_visibility), and keeps their mean
 * (scene_trace.comp): the penumbra.
 */
#ifndef SB_SHADOWS_GLSL
#define SB_SHADOWS_GLSL

#include "view_gpu.h"
#include "view.glsl"

/* The key light's angular radius (radians). */
float key_radius()
{
    return key_light() == 0 ? frame.sun_direction.w : frame.moon_direction.w;
}

/* Point i of n on Vogel's spiral, spread evenly over the unit disk, turned
 * by `turn` (radians). */
vec2 vogel(int i, int n, float turn)
{
    float r = sqrt((float(i) + 0.5) / float(n));
    float a = float(i) * 2.39996323 + turn; /* the golden angle */
    return r * vec2(cos(a), sin(a));
}

/* A per-pixel turn in [0, 2 pi). */
float pixel_turn(vec2 pixel)
{
    return 6.2831853 * interleaved_noise(pixel);
}

#ifdef SB_TRACED_SHADOWS
layout(std430, set = 0, binding = SB_VIEW_BINDING_BVH_NODES) readonly buffer BvhNodes { vec4 bvh_nodes[]; };
layout(std430, set = 0, binding = SB_VIEW_BINDING_BVH_TRIANGLES) readonly buffer BvhTriangles { vec4 bvh_triangles[]; };
#define BVH_ANY_HIT_MATERIAL_0_PASSES /* receivers only (a ground) cast no shadow, as in the maps */
#include "bvh.glsl"

/* A shadow ray from the point `offset` m from the camera toward unit l: 1
 * when no caster ends it. */
float shadow_ray(vec3 offset, vec3 n, vec3 l)
{
    vec3 c = abs(frame.camera_m.xyz), p = offset + frame.camera_m.xyz;
    /* Off the surface, to the side the light is on, by 1 mm and 4e-6 of the
     * scale of the point's rounding: it was found from the camera at
     * `offset` (a ray's t) and placed in the world (fp32 steps of |p| <=
     * |camera| + |offset|), so the lift stays a fixed fraction of a pixel's
     * footprint however far the camera is. */
    float lift = 1e-3 + 4e-6 * (max(c.x, max(c.y, c.z)) + length(offset));
    vec3 o = p + n * (dot(n, l) < 0.0 ? -lift : lift);
    return bvh_trace(o, l, 0.0, SB_TRACE_FAR_M, true).triangle == SB_BVH_MISS ? 1.0 : 0.0;
}

/* Toward the key light's centre. `pcf` is the raster's: a ray needs no filter. */
float sun_visibility(vec3 offset, vec3 n, bool pcf)
{
    if (frame.shadow.w == 0.0)
        return 1.0;
    return shadow_ray(offset, n, key_direction());
}

/* A ray toward point k of n on the key light's disk (Vogel's spiral, turned
 * by `turn`), k = 0 its centre. */
float disk_visibility(vec3 offset, vec3 n, int k, int count, float turn)
{
    if (frame.shadow.w == 0.0)
        return 1.0;
    vec3 l = key_direction();
    if (k == 0)
        return shadow_ray(offset, n, l);
    vec3 e1 = normalize(cross(l, abs(l.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0))), e2 = cross(l, e1);
    vec2 o = vogel(k, count, turn) * tan(key_radius());
    return shadow_ray(offset, n, normalize(l + o.x * e1 + o.y * e2));
}
#else

layout(set = 0, binding = SB_VIEW_BINDING_SHADOW) uniform sampler2DArrayShadow shadow_map;

/* Map c's matrix, texel (m) and casters' uv box: a cascade's, or for c =
 * SB_CASCADES the far map's (fitted to the casters: its whole). */
mat4 shadow_matrix(int c)
{
    return c < SB_CASCADES ? frame.shadow_view_proj[c] : frame.far_view_proj;
}

float shadow_texel(int c)
{
    return c < SB_CASCADES ? frame.cascade_texel[c] : frame.far_shadow.x;
}

vec4 shadow_rect(int c)
{
    return c < SB_CASCADES ? frame.cascade_rect[c] : vec4(0.0, 0.0, 1.0, 1.0);
}

/* Tap i of 4 of the fixed filter about uv in a map of `size` texels: its
 * uv and weight (the four sum to 9). 3 x 3 bilinear taps a texel apart
 * weigh the 4 x 4 texels from base - 1 by (1 - f, 1, 1, f) / 3 in each axis
 * (f: the point's fraction past texel base). Two bilinear taps give the
 * same weights, one on the first pair (2 - f of them, 1 / (2 - f) of the
 * way across) and one on the last (1 + f, f / (1 + f) across): 2 x 2 taps
 * instead of 3 x 3 (Castano 2013), the same filter up to the sampler's
 * rounding of its weights. f is rounded to 1/256, a GPU sampler's own
 * precision, so that the four weights and their sum are exact: a region
 * all lit or all shadowed reads exactly 1 or 0. */
vec2 fixed_tap(int i, vec2 uv, float size, out float weight)
{
    vec2 x = uv * size - 0.5, base = floor(x), f = floor((x - base) * 256.0 + 0.5) / 256.0;
    vec2 w0 = 2.0 - f, w1 = 1.0 + f;
    vec2 p0 = (base - 0.5 + 1.0 / w0) / size, p1 = (base + 1.5 + f / w1) / size;
    bvec2 second = bvec2((i & 1) != 0, i >= 2);
    vec2 w = mix(w0, w1, second);
    weight = w.x * w.y;
    return mix(p0, p1, second);
}

#ifdef SB_SOFT_SHADOWS
/*
 * Penumbrae (percentage-closer soft shadows, Fernando 2005), for the
 * scene: the key light is a disk of angular radius alpha, so a blocker d
 * metres before the receiver blurs its edge over d tan(alpha) each side.
 * A blocker search over the disk of map texels from which a blocker within
 * the cascade's depth could reach the point (at most
 * SB_SHADOW_SEARCH_TEXELS), SB_SHADOW_SEARCH_TAPS gathers of 2 x 2 texels,
 * gives the mean blocker depth, then SB_SHADOW_FILTER_TAPS bilinear comparisons over a
 * disk of the penumbra's radius: a straight edge at one distance then reads
 * the fraction of the light's disk it leaves uncovered, its true profile.
 * The taps lie on Vogel's spiral turned by a per-pixel noise. Each tap is
 * compared against the receiver's plane through the point (its normal in
 * the map's space), not its depth at the centre, so that a wide filter on
 * a surface sloped to the light does not shadow itself (the acne at a low
 * light). Penumbrae under a texel take the 4-tap filter below.
 */
layout(set = 0, binding = SB_VIEW_BINDING_SHADOW_DEPTH) uniform sampler2DArray shadow_depth;

/* The receiver's depth (the map's 0 to 1) a uv step away, on the plane
 * through the point with normal n: the cascade's clip space is an affine map
 * M of the world, so the plane's normal there is M^-T n, and for M = S R (a
 * rotation, then scales) that is S^-2 (M n). A plane steeper than 10 texels
 * of depth a texel is grazing the light: its slope is held there (the normal
 * offset covers the rest), so that a tap on it does not compare against a
 * depth far from any surface. */
vec2 receiver_slope(int c, vec3 n, float texel_m, float range_m)
{
    mat3 m = mat3(frame.shadow_view_proj[c]);
    vec3 mn = m * n;
    vec3 s2 = vec3(dot(vec3(m[0][0], m[1][0], m[2][0]), vec3(m[0][0], m[1][0], m[2][0])),
                   dot(vec3(m[0][1], m[1][1], m[2][1]), vec3(m[0][1], m[1][1], m[2][1])),
                   dot(vec3(m[0][2], m[1][2], m[2][2]), vec3(m[0][2], m[1][2], m[2][2])));
    vec3 nc = mn / s2;
    if (abs(nc.z) < 1e-20)
        return vec2(0.0);
    /* uv = clip.xy / 2 + 1/2: a uv step is two clip steps */
    vec2 slope = -2.0 * nc.xy / nc.z;
    float limit = 10.0 * texel_m * frame.shadow.z / range_m, length_ = length(slope);
    return length_ > limit ? slope * (limit / length_) : slope;
}

float soft_visibility(int c, vec3 offset, vec3 n, vec3 s, vec2 uv)
{
    float size = frame.shadow.z, texel_m = frame.cascade_texel[c], range_m = frame.cascade_depth_m[c];
    float tan_a = tan(key_radius());
    vec2 slope = receiver_slope(c, n, texel_m, range_m);
    vec4 clip = frame.view_proj * vec4(offset, 1.0);
    vec2 px = (clip.xy / clip.w * 0.5 + 0.5) * vec2(frame.size.xy);
    float turn = pixel_turn(px);
    /* the map's own quantum and the raster's depth bias: what a blocker must be nearer by */
    const float epsilon = 2.0 / 65535.0;

    float search = min(range_m * tan_a / texel_m, float(SB_SHADOW_SEARCH_TEXELS)) / size;
    float blockers = 0.0, depth_sum = 0.0;
    vec4 rect = frame.cascade_rect[c];
    for (int i = 0; i < SB_SHADOW_SEARCH_TAPS; i++) {
        vec2 o = vogel(i, SB_SHADOW_SEARCH_TAPS, turn) * search, q = uv + o;
        if (any(lessThan(q, rect.xy)) || any(greaterThan(q, rect.zw)))
            continue; /* outside the casters' box: none */
        vec4 z = textureGather(shadow_depth, vec3(q, float(c)), 0); /* the 2 x 2 texels around q */
        vec4 blocking = vec4(lessThan(z, vec4(s.z + dot(slope, o) - epsilon)));
        blockers += dot(blocking, vec4(1.0));
        depth_sum += dot(blocking, z);
    }
    float distance_m = blockers > 0.0 ? max(s.z - depth_sum / blockers, 0.0) * range_m : 0.0;
    float radius = min(distance_m * tan_a / texel_m, float(SB_SHADOW_SEARCH_TEXELS)) / size;
    /* Then one loop of taps: the penumbra's, or where it is under a texel
     * the fixed filter's four (fixed_tap), or none where no blocker was
     * found (lit). One loop, not a branch for each filter: llvmpipe runs a
     * branch's code whether or not an invocation takes it, but ends a loop
     * when none of its SIMD group goes on (the scene pass 31 -> 27 ms at
     * 640 x 360). */
    bool penumbra = radius * size >= 1.0;
    /* a point outside the casters' box that a penumbra does not reach: lit */
    bool outside_box = any(lessThan(uv, rect.xy)) || any(greaterThan(uv, rect.zw));
    int taps = blockers == 0.0 || (!penumbra && outside_box) ? 0 : (penumbra ? SB_SHADOW_FILTER_TAPS : 4);
    float sum = 0.0, total = 0.0;
    for (int i = 0; i < taps; i++) {
        float weight = 1.0;
        vec2 o = vogel(i, SB_SHADOW_FILTER_TAPS, turn) * radius, q = uv + o;
        if (!penumbra) {
            q = fixed_tap(i, uv, size, weight);
            o = vec2(0.0);
        }
        bool outside = any(lessThan(q, rect.xy)) || any(greaterThan(q, rect.zw));
        sum += weight * (outside && penumbra ? 1.0 : textureGrad(shadow_map, vec4(q, float(c), s.z + dot(slope, o)),
                                                                  vec2(0.0), vec2(0.0)));
        total += weight;
    }
    return taps == 0 ? 1.0 : sum / total;
}
#endif

float cascade_visibility(int c, vec3 offset, vec3 n, bool pcf)
{
    vec3 p = offset + n * (shadow_texel(c) * frame.shadow.y);
    vec4 clip = shadow_matrix(c) * vec4(p, 1.0);
    vec3 s = clip.xyz / clip.w;
    vec2 uv = s.xy * 0.5 + 0.5;
    vec4 rect = shadow_rect(c);
    /* A penumbra reaches past the casters' box by its filter's radius. */
    float reach = 0.0;
#ifdef SB_SOFT_SHADOWS
    if (pcf && c < SB_CASCADES)
        reach = float(SB_SHADOW_SEARCH_TEXELS) / frame.shadow.z;
#endif
    if (any(lessThan(uv, max(rect.xy - reach, vec2(0.0)))) || any(greaterThan(uv, min(rect.zw + reach, vec2(1.0)))) ||
        s.z > 1.0)
        return 1.0;
    if (!pcf)
        return textureGrad(shadow_map, vec4(uv, float(c), s.z), vec2(0.0), vec2(0.0));
#ifdef SB_SOFT_SHADOWS
    if (dot(n, key_direction()) <= 0.0)
        return 0.0; /* turned from the light: none of it, and no search */
    if (c < SB_CASCADES)
        return soft_visibility(c, offset, n, s, uv);
    /* the far map: the fixed filter */
#endif
    float sum = 0.0;
    for (int i = 0; i < 4; i++) {
        float weight;
        vec2 q = fixed_tap(i, uv, frame.shadow.z, weight);
        sum += weight * textureGrad(shadow_map, vec4(q, float(c), s.z), vec2(0.0), vec2(0.0));
    }
    return sum / 9.0;
}

float sun_visibility(vec3 offset, vec3 n, bool pcf)
{
    if (frame.shadow.w == 0.0)
        return 1.0;
    float depth = dot(offset, frame.camera_forward.xyz);
    /* past the last cascade, the far map where it is drawn */
    int c = 0, maps = frame.far_shadow.w > 0.0 ? SB_CASCADES + 1 : SB_CASCADES;
    while (c < SB_CASCADES && depth > frame.cascade_ends[c])
        c++;
    if (c == SB_CASCADES)
        return maps > SB_CASCADES ? cascade_visibility(c, offset, n, pcf) : 1.0;
    float begin = c == 0 ? 0.0 : frame.cascade_ends[c - 1];
    float band = frame.shadow.x * (frame.cascade_ends[c] - begin);
    float f = band > 0.0 ? (depth - (frame.cascade_ends[c] - band)) / band : 0.0;
    /* In the band, toward the next cascade, or the far map past the last
     * (out of the shadows without one). The next map is read in a loop's
     * second turn, not in a branch: llvmpipe runs a branch's code whether
     * or not an invocation takes it, but ends a loop when none of its SIMD
     * group goes on, and few groups meet a band (lavapipe's scene pass 46
     * -> 41 ms at 640 x 360). */
    float visibility = 1.0, next = 1.0;
    int last = f > 0.0 && c + 1 < maps ? c + 1 : c;
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
