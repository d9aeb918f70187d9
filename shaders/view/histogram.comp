#version 450
/* Log-luminance histogram of the frame (before exposure): bin 0 holds
 * luminance below 2^exposure.x (and black), bins 1 to 255 split
 * [exposure.x, exposure.x + exposure.y] evenly in log2. Counts go to shared
 * memory first, then once per workgroup to the buffer. A pixel that sees
 * only space (a camera above the atmosphere, its ray missing it) is left
 * out: from orbit half a frame can be black space, which dragged the
 * meter's mean some 14 stops under the lit planet and left it white. */
#extension GL_GOOGLE_include_directive : require
#define SB_MOONLESS /* no light is read */
#include "view_gpu.h"
#include "view.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
layout(std430, set = 0, binding = SB_VIEW_BINDING_EXPOSURE) buffer ExposureBuffer {
    uint bins[SB_HISTOGRAM_BINS];
    sb_exposure_gpu exposure;
};
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform readonly image2D hdr;

shared uint local_bins[SB_HISTOGRAM_BINS];

/* True when the pixel's ray, from a camera above the atmosphere, misses it. */
bool sees_space(ivec2 pixel)
{
    return atmosphere_entry(frame.camera_km.xyz, view_ray((vec2(pixel) + 0.5) / vec2(frame.size.xy))) < 0.0;
}

void main()
{
    local_bins[gl_LocalInvocationIndex] = 0u;
    barrier();
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (all(lessThan(uvec2(pixel), frame.size.xy)) && !sees_space(pixel)) {
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
