#version 450
/* Auto-exposure from the histogram: the mean log2 luminance of the pixels
 * between the low and high percentiles (so neither the sun nor deep shadow
 * decides), held within the EV range, adapted in log2 toward it at
 * exponential speeds per second, then the exposure that maps it to mid grey
 * (0.18) with the compensation, less the dim light's: a night stays darker
 * than a day, as the eye sees it. The bins are cleared for the next frame. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"

layout(local_size_x = SB_HISTOGRAM_BINS) in;
#include "frame.glsl"
layout(std430, set = 0, binding = SB_VIEW_BINDING_EXPOSURE) buffer ExposureBuffer {
    uint bins[SB_HISTOGRAM_BINS];
    sb_exposure_gpu exposure;
};

shared uint counts[SB_HISTOGRAM_BINS];

void main()
{
    uint i = gl_LocalInvocationIndex;
    counts[i] = bins[i];
    barrier();
    if (i != 0u)
        return;
    float total = 0.0; /* the metered pixels (histogram.comp leaves space out) */
    for (uint b = 0u; b < SB_HISTOGRAM_BINS; b++)
        total += float(counts[b]);
    float low = frame.exposure.z * total, high = frame.exposure.w * total;
    float below = 0.0, weight = 0.0, sum = 0.0;
    for (uint b = 0u; b < SB_HISTOGRAM_BINS; b++) {
        float c = float(counts[b]);
        /* The part of this bin inside [low, high] of the sorted pixels. */
        float in_window = clamp(below + c, low, high) - clamp(below, low, high);
        below += c;
        if (in_window <= 0.0)
            continue;
        float bin_log = b == 0u ? frame.exposure.x - 1.0
                                : frame.exposure.x + (float(b) - 0.5) / float(SB_HISTOGRAM_BINS - 2) * frame.exposure.y;
        sum += in_window * bin_log;
        weight += in_window;
    }
    float metered = clamp(weight > 0.0 ? sum / weight : frame.exposure.x, frame.meter.x, frame.meter.y);
    float adapted = metered;
    if (frame.adaptation.w == 0.0) {
        float previous = exposure.state.x;
        float speed = metered > previous ? frame.adaptation.x : frame.adaptation.y;
        adapted = previous + (metered - previous) * (1.0 - exp(-frame.adaptation.z * speed));
    }
    float dim = frame.meter.z * max(frame.meter.w - adapted, 0.0);
    exposure.state = vec4(adapted, 0.18 * exp2(frame.post.z - dim - adapted), metered, weight);
    for (uint b = 0u; b < SB_HISTOGRAM_BINS; b++)
        bins[b] = 0u;
}
