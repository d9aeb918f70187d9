#version 450
/* Front-to-back integration of a froxel column (Hillaire 2015): each slice's
 * medium is constant over its length along the view ray, so its light adds
 * S (1 - e^(-sigma l)) / sigma, energy-conserving whatever the slice's
 * optical depth, and the transmittance is multiplied by e^(-sigma l).
 * Texel k holds the in-scattering (rgb) and transmittance (a) from the
 * camera to the end of slice k. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "view.glsl"
#include "fog.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_FROXEL_LIGHT_OUT, rgba16f) uniform readonly image3D light;
layout(set = 0, binding = SB_VIEW_BINDING_FROXEL_OUT, rgba16f) uniform writeonly image3D integrated;

void main()
{
    uvec2 column = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(column, fog.grid.xy)))
        return;
    vec3 inscatter = vec3(0.0);
    float transmittance = 1.0;
    float begin = 0.0;
    /* Lengths along the ray through the column's centre; the slices are
     * spherical shells, so every ray of the column crosses the same. */
    for (uint k = 0u; k < fog.grid.z; k++) {
        float end = froxel_distance(float(k + 1u) / float(fog.grid.z));
        vec4 v = imageLoad(light, ivec3(column, k));
        float sigma = max(v.a, 0.0), l = end - begin;
        float tau = sigma * l;
        /* (1 - e^-tau) / sigma, and l where tau is too small to divide */
        float path = tau > 1e-4 ? (1.0 - exp(-tau)) / sigma : l * (1.0 - 0.5 * tau);
        inscatter += transmittance * v.rgb * path;
        transmittance *= exp(-tau);
        imageStore(integrated, ivec3(column, k), vec4(fp16_safe(inscatter), transmittance));
        begin = end;
    }
}
