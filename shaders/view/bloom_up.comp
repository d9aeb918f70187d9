#version 450
/* One step up the bloom chain: add a 3x3 tent of the coarser level (already
 * accumulated) to this level's downsampled content. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_BLOOM_SRC) uniform sampler2D src;
layout(set = 0, binding = SB_VIEW_BINDING_BLOOM_DST, rgba16f) uniform image2D dst;

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(dst);
    if (any(greaterThanEqual(pixel, size)))
        return;
    vec2 uv = (vec2(pixel) + 0.5) / vec2(size);
    vec2 t = 1.0 / vec2(textureSize(src, 0));
    vec3 sum = vec3(0.0);
    for (int j = -1; j <= 1; j++)
        for (int i = -1; i <= 1; i++)
            sum += textureLod(src, uv + vec2(i, j) * t, 0.0).rgb * float((2 - abs(i)) * (2 - abs(j)));
    vec3 c = imageLoad(dst, pixel).rgb + sum / 16.0;
    imageStore(dst, pixel, vec4(min(c, vec3(65000.0)), 1.0));
}
