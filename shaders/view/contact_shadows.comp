#version 450
/* Screen-space contact shadows (raster scene only; the traced scene's
 * shadow rays are exact): from each pixel of the world, a short march
 * toward the key light through the depth buffer, SB_CONTACT_STEPS steps
 * over a reach of SB_CONTACT_REACH of the pixel's distance (at most
 * SB_CONTACT_MAX_M), jittered per pixel. A step whose point lies behind
 * the depth buffer's surface (in view depth) by less than a thickness
 * (SB_CONTACT_THICKNESS of its depth, at least SB_CONTACT_MIN_THICKNESS_M)
 * is in a caster's shadow: the caster the cascades' texels and bias miss (a leg on a floor,
 * a book on a table). Where a step finds one, the key light's direct share
 * of the pixel (scene.frag's second target) is taken back, faded over the
 * reach's last quarter. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_DEPTH) uniform sampler2D scene_depth;
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform image2D hdr;
layout(set = 0, binding = SB_VIEW_BINDING_KEY_LIGHT, rgba16f) uniform readonly image2D key_share;

/* The camera-relative point (m) at uv whose depth is `depth` (reverse Z). */
vec3 point_at(vec2 uv, float depth)
{
    vec4 p = frame.inv_view_proj * vec4(uv * 2.0 - 1.0, depth, 1.0);
    return p.xyz / p.w;
}

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec3 key = imageLoad(key_share, pixel).rgb;
    float depth = texelFetch(scene_depth, pixel, 0).r;
    if (depth <= 0.0 || max(key.r, max(key.g, key.b)) <= 0.0)
        return;
    vec2 size = vec2(frame.size.xy);
    vec3 p = point_at((vec2(pixel) + 0.5) / size, depth);
    float reach = min(SB_CONTACT_REACH * length(p), SB_CONTACT_MAX_M);
    /* the march in clip space, where it is linear: a step's w is its view
     * depth, and a depth d of the buffer (reverse Z, infinitely far) lies
     * at view depth near / d */
    vec4 c0 = frame.view_proj * vec4(p, 1.0), c1 = frame.view_proj * vec4(key_direction() * reach, 0.0);
    float near = frame.camera_m.w;
    float jitter = interleaved_noise(vec2(pixel));
    float shadow = 0.0;
    for (int i = 0; i < SB_CONTACT_STEPS; i++) {
        float t = (float(i) + jitter) / float(SB_CONTACT_STEPS);
        vec4 clip = c0 + t * c1;
        if (clip.w <= near)
            break;
        vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
        if (any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(1.0))))
            break;
        /* the 2 x 2 depths around the step: it must lie behind the
         * farthest of them (a surface seen at a grazing angle spans a
         * range of depths within a pixel, which a single texel would take
         * for a caster) and within the thickness of the nearest */
        vec4 seen = textureGather(scene_depth, uv, 0);
        float farthest = min(min(seen.x, seen.y), min(seen.z, seen.w));
        float nearest = max(max(seen.x, seen.y), max(seen.z, seen.w));
        if (farthest <= 0.0)
            continue;
        float z = clip.w, behind = z - near / farthest, inside = z - near / nearest;
        if (behind > SB_CONTACT_BIAS * z && inside < max(SB_CONTACT_THICKNESS * z, SB_CONTACT_MIN_THICKNESS_M)) {
            shadow = clamp((1.0 - t) * 4.0, 0.0, 1.0);
            break;
        }
    }
    if (shadow > 0.0) {
        vec4 c = imageLoad(hdr, pixel);
        imageStore(hdr, pixel, vec4(max(c.rgb - shadow * key, vec3(0.0)), c.a));
    }
}
