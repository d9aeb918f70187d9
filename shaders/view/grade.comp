#version 450
/* Colour grading through a 3D LUT (a .cube file, formats/lut3d.h) on the
 * display-referred frame: the tone-mapped, sRGB-encoded 8-bit pixels, as
 * DaVinci Resolve applies a .cube to an sRGB clip. Each pixel's code q
 * goes in as q / 255 (scaled from the LUT's domain to its nodes), comes
 * out by trilinear interpolation and is rounded to the nearest code, so a
 * neutral LUT returns every code unchanged. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "lut3d.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
#include "frame.glsl"
layout(set = 0, binding = SB_VIEW_BINDING_LDR, rgba8) uniform image2D ldr;

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec4 v = imageLoad(ldr, pixel);
    vec3 g = lut_apply(v.rgb);
    imageStore(ldr, pixel, vec4(floor(clamp(g, 0.0, 1.0) * 255.0 + 0.5) / 255.0, v.a));
}
