#version 450
/* The Purkinje shift (runtime/passes/purkinje.c), in place on the lit frame
 * before exposure: in dim light the rods add their response to the cones',
 * and a night scene looks blue, not grey.
 *
 * The model is Kirk and O'Brien's (2011, after Cao et al. 2008) as Patry
 * reduced it for Ghost of Tsushima (SIGGRAPH 2021, "Real-Time Samurai
 * Cinema"): linear Rec.709 radiance in cd/m^2 gives the cones' and rods'
 * responses q = (L, M, S, R); each cone's gain is 1 / sqrt(1 + q_cone);
 * the rods' signal R, through those gains and the opponent channels, adds
 * R * C * gain to the colour (C folds the opponent transform back to RGB).
 * The shift is then weighted by where the pixel's luminance Y lies between
 * the photopic and scotopic limits, linearly in log Y: none at or above
 * the photopic (the cones alone: the frame is left exactly as it was), all
 * of it at or below the scotopic. */
#extension GL_GOOGLE_include_directive : require
#include "purkinje_gpu.h"
#include "view_gpu.h"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
#include "frame.glsl"
layout(std430, set = 0, binding = SB_VIEW_BINDING_PURKINJE) readonly buffer PurkinjeBuffer {
    sb_purkinje_gpu purkinje;
};
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform image2D hdr;

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec4 h = imageLoad(hdr, pixel);
    vec3 c = max(h.rgb, vec3(0.0)) * purkinje.scale.x; /* cd/m^2 */
    float y = dot(c, vec3(SB_LUMINANCE_RGB));
    float photopic = purkinje.scale.z, scotopic = purkinje.scale.w;
    if (!(y < photopic))
        return;
    float weight = min(log2(photopic / max(y, 1e-30)) / log2(photopic / scotopic), 1.0);
    /* Rows: L, M, S and R from linear Rec.709 (Patry 2021). */
    vec3 lms = vec3(dot(c, vec3(0.31670331, 0.70299344, 0.08120592)), dot(c, vec3(0.10129085, 0.72118661, 0.12041039)),
                    dot(c, vec3(0.01451538, 0.05643031, 0.53416779)));
    float rod = dot(c, vec3(0.01724063, 0.60147464, 0.40056206));
    vec3 gain = inversesqrt(1.0 + lms);
    vec3 shift = rod * vec3(dot(gain, vec3(4.57829597, -4.48749114, 0.31554848)),
                            dot(gain, vec3(-0.63342362, 2.03236026, -0.36183302)),
                            dot(gain, vec3(-0.05749394, -0.09275939, 1.90172089)));
    imageStore(hdr, pixel, vec4(h.rgb + weight * shift * purkinje.scale.y, h.a));
}
