#version 450
/* Log-luminance histogram of the frame (before exposure): bin 0 holds
 * luminance below 2^exposure.x (and black), bins 1 to 255 split
 * [exposure.x, exposure.x + exposure.y] evenly in log2. Counts go to shared
 * memory first, then once per workgroup to the buffer. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"

layout(local_size_x = 16, local_size_y = 16) in;
#include "frame.glsl"
layout(std430, set = 0, binding = SB_VIEW_BINDING_EXPOSURE) buffer ExposureBuffer {
    uint bins[SB_HISTOGRAM_BINS];
    sb_exposure_gpu exposure;
};
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform readonly image2D hdr;

shared uint local_bins[SB_HISTOGRAM_BINS];

void main()
{
    local_bins[gl_LocalInvocationIndex] = 0u;
    barrier();
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (all(lessThan(uvec2(pixel), frame.size.xy))) {
        /* Radiance as stored, back in the scene's units. */
        float lum = dot(imageLoad(hdr, pixel).rgb, vec3(SB_LUMINANCE_RGB)) / frame.aerial.y;
        uint bin = 0u;
        if (lum > 0.0) {
            float x = (log2(lum) - frame.exposure.x) / frame.exposure.y;
            if (x >= 0.0)
                bin = uint(clamp(1.0 + x * float(SB_HISTOGRAM_BINS - 2), 1.0, float(SB_HISTOGRAM_BINS - 1)));
        }
        atomicAdd(local_bins[bin], 1u);
    }
    barrier();
    uint count = local_bins[gl_LocalInvocationIndex];
    if (count != 0u)
        atomicAdd(bins[gl_LocalInvocationIndex], count);
}
