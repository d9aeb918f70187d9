#version 450
/* The clouds at full resolution from this frame's traced pixels and the
 * last frame's result (Schneider 2015's quarter-resolution reprojection):
 * - where the scene ends before the layer begins, no clouds;
 * - a traced pixel blends its new value with the history, 1 - w : w,
 *   w = min(0.8, k / (k + 1)) after k traces of it since the history
 *   began: its own samples averaged, then an exponential average (the
 *   first frame's neighbours, which stood in for it, leave no trace);
 * - any other pixel keeps the history;
 * - the history is read where the pixel's clouds (at their traced
 *   distance) were in the last frame, and clamped to the range of this
 *   frame's 3 x 3 traced pixels around it, so what moved or changed does
 *   not trail (the usual neighbourhood clamp of temporal antialiasing),
 *   that range widened by its own size where the history has not moved
 *   and by less up to a pixel of motion;
 * - without history (a cut, the first frame, off the last frame), this
 *   frame's traced pixels, bilinearly.
 * Then composited: colour T + S (S carries the aerial perspective). */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"
#include "cloud_layer.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_DEPTH) uniform sampler2D scene_depth;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_TRACE) uniform sampler2D trace;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_DEPTH) uniform sampler2D trace_depth;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_HISTORY) uniform sampler2D history;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_OUT, rgba16f) uniform writeonly image2D clouds_out;
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform image2D hdr;

vec4 resolve(ivec2 pixel, vec2 uv, vec3 d)
{
    float depth = texelFetch(scene_depth, pixel, 0).r;
    float t0, t1;
    bool layer = cloud_segment(d, t0, t1);
    if (depth > 0.0) {
        vec4 at = frame.inv_view_proj * vec4(uv * 2.0 - 1.0, depth, 1.0);
        layer = layer && length(at.xyz / at.w) > t0;
    }
    if (!layer)
        return vec4(0.0, 0.0, 0.0, 1.0);

    int s = int(clouds.trace.z);
    ivec2 sub = ivec2(clouds.trace.w % clouds.trace.z, clouds.trace.w / clouds.trace.z);
    ivec2 size = ivec2(clouds.trace.xy);
    ivec2 block = min(pixel / s, size - 1);
    bool traced = all(equal(pixel, min(block * s + sub, ivec2(frame.size.xy) - 1)));
    vec4 current = traced ? texelFetch(trace, block, 0)
                          : textureLod(trace, (vec2(pixel - sub) / float(s) + 0.5) / vec2(size), 0.0);
    float weight = clouds.temporal.y;
    if (weight <= 0.0)
        return current;
    vec3 before = d * texelFetch(trace_depth, block, 0).r + clouds.camera_motion_m.xyz;
    vec4 clip = clouds.previous_view_proj * vec4(before, 1.0);
    vec2 then = clip.xy / clip.w * 0.5 + 0.5;
    if (clip.w <= 0.0 || any(lessThan(then, vec2(0.0))) || any(greaterThan(then, vec2(1.0))))
        return current;
    vec4 lo = vec4(1e30), hi = vec4(-1e30);
    for (int j = -1; j <= 1; j++)
        for (int i = -1; i <= 1; i++) {
            vec4 v = texelFetch(trace, clamp(block + ivec2(i, j), ivec2(0), size - 1), 0);
            lo = min(lo, v);
            hi = max(hi, v);
        }
    /* Where the history stays in place, the box is widened by its own size:
     * a pixel's own extremes, which its traced neighbours lack, survive. */
    float moved_px = length((then - uv) * vec2(frame.size.xy));
    vec4 widen = (hi - lo) * clamp(1.0 - moved_px, 0.0, 1.0);
    vec4 kept = clamp(textureLod(history, then, 0.0) * vec4(vec3(clouds.temporal.w), 1.0), lo - widen, hi + widen);
    float k = floor(clouds.temporal.z / float(s * s)); /* this pixel's traces before this frame */
    return traced ? mix(current, kept, min(weight, k / (k + 1.0))) : kept;
}

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec2 uv = (vec2(pixel) + 0.5) / vec2(frame.size.xy);
    vec4 value = resolve(pixel, uv, view_ray(uv));
    imageStore(clouds_out, pixel, value);
    vec3 colour = imageLoad(hdr, pixel).rgb;
    if (frame.size.w == SB_DEBUG_CLOUDS)
        colour = value.rgb;
    else if (frame.size.w == SB_DEBUG_CLOUD_TRANSMITTANCE)
        colour = vec3(value.a * frame.aerial.y); /* read back divided by the scale */
    else if (frame.size.w == SB_DEBUG_NONE || frame.size.w == SB_DEBUG_ENV_SPECULAR)
        colour = colour * value.a + value.rgb;
    imageStore(hdr, pixel, vec4(fp16_safe(colour), 1.0));
}
