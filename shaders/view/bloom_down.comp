#version 450
/* One step down the bloom chain (Jimenez 2014, "Next generation post
 * processing in Call of Duty"): 13 bilinear taps as five overlapping 2x2
 * boxes. The first step reads the frame, exposes it, keeps what is above the
 * threshold (a soft knee) and weights the boxes by 1 / (1 + luma) (Karis's
 * average) so that single bright pixels such as the sun do not flicker. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
#include "frame.glsl"
layout(std430, set = 0, binding = SB_VIEW_BINDING_EXPOSURE) readonly buffer ExposureBuffer {
    uint bins[SB_HISTOGRAM_BINS];
    sb_exposure_gpu exposure;
};
layout(push_constant) uniform ViewPush {
    sb_view_push pc;
};
layout(set = 0, binding = SB_VIEW_BINDING_BLOOM_SRC) uniform sampler2D src;
layout(set = 0, binding = SB_VIEW_BINDING_BLOOM_DST, rgba16f) uniform writeonly image2D dst;

float luma(vec3 c)
{
    return dot(c, vec3(SB_LUMINANCE_RGB));
}

vec3 prepare(vec3 c)
{
    if (pc.first_level == 0u)
        return c;
    c *= exposure.state.y / frame.aerial.y;
    float threshold = frame.post.x, knee = 0.5 * threshold;
    float l = luma(c);
    float soft = clamp(l - threshold + knee, 0.0, 2.0 * knee);
    soft = soft * soft / (4.0 * knee + 1e-5);
    float keep = max(soft, l - threshold) / max(l, 1e-5);
    return c * keep;
}

vec3 tap(vec2 uv, vec2 t, float x, float y)
{
    return prepare(textureLod(src, uv + vec2(x, y) * t, 0.0).rgb);
}

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(dst);
    if (any(greaterThanEqual(pixel, size)))
        return;
    vec2 uv = (vec2(pixel) + 0.5) / vec2(size);
    vec2 t = 1.0 / vec2(textureSize(src, 0));
    /* the 13 taps, each read once: four inner, nine on the outer lattice */
    vec3 i00 = tap(uv, t, -1, -1), i10 = tap(uv, t, 1, -1), i01 = tap(uv, t, -1, 1), i11 = tap(uv, t, 1, 1);
    vec3 o00 = tap(uv, t, -2, -2), o10 = tap(uv, t, 0, -2), o20 = tap(uv, t, 2, -2);
    vec3 o01 = tap(uv, t, -2, 0), o11 = tap(uv, t, 0, 0), o21 = tap(uv, t, 2, 0);
    vec3 o02 = tap(uv, t, -2, 2), o12 = tap(uv, t, 0, 2), o22 = tap(uv, t, 2, 2);
    vec3 boxes[5] = vec3[5](0.25 * (i00 + i10 + i01 + i11), /* centre */
                            0.25 * (o00 + o10 + o01 + o11), /* corners */
                            0.25 * (o10 + o20 + o11 + o21), 0.25 * (o01 + o11 + o02 + o12),
                            0.25 * (o11 + o21 + o12 + o22));
    const float weights[5] = float[5](0.5, 0.125, 0.125, 0.125, 0.125);
    vec3 sum = vec3(0.0);
    float norm = 0.0;
    for (int i = 0; i < 5; i++) {
        float w = weights[i] * (pc.first_level != 0u ? 1.0 / (1.0 + luma(boxes[i])) : 1.0);
        sum += w * boxes[i];
        norm += w;
    }
    imageStore(dst, pixel, vec4(min(sum / norm, vec3(65000.0)), 1.0));
}
