#version 450
/*
 * Cloud noise: one texel per invocation, each channel by its recipe
 * (config.h's sb_noise_push; definitions in baker/clouds.h).
 */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#include "noise.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y, local_size_z = 1) in;
layout(push_constant) uniform Push { sb_noise_push pc; };
layout(std430, set = 0, binding = 0) writeonly buffer Output { float result[]; };

/* The curl of the potential (perlin_fbm with seeds seed, seed + 16,
 * seed + 32) by central differences, step 2^-12; component `axis`. */
float curl(vec3 p, int period, int octaves, uint seed, uint axis)
{
    const float h = 1.0 / 4096.0;
    /* component i of the potential differentiated along axis j */
    uint i0 = (axis + 2u) % 3u, j0 = (axis + 1u) % 3u; /* d psi_i0 / d x_j0 */
    uint i1 = (axis + 1u) % 3u, j1 = (axis + 2u) % 3u; /* minus d psi_i1 / d x_j1 */
    vec3 e0 = vec3(j0 == 0u, j0 == 1u, j0 == 2u) * h, e1 = vec3(j1 == 0u, j1 == 1u, j1 == 2u) * h;
    precise float d0 = noise_perlin_fbm(p + e0, period, octaves, seed + 16u * i0) -
                       noise_perlin_fbm(p - e0, period, octaves, seed + 16u * i0);
    precise float d1 = noise_perlin_fbm(p + e1, period, octaves, seed + 16u * i1) -
                       noise_perlin_fbm(p - e1, period, octaves, seed + 16u * i1);
    /* (d0 - d1) / (2 h), mapped to 1/2 + curl / 16 */
    precise float v = 0.5 + (d0 - d1) * (2048.0 / 16.0);
    return clamp(v, 0.0, 1.0);
}

void main()
{
    uvec3 id = gl_GlobalInvocationID;
    if (id.x >= pc.size_x || id.y >= pc.size_y || id.z >= pc.size_z)
        return;
    precise vec3 p = (vec3(id) + 0.5) * vec3(pc.inv_x, pc.inv_y, pc.inv_z);
    if (pc.size_z == 1u)
        p.z = pc.slice_z;
    uint base = ((id.z * pc.size_y + id.y) * pc.size_x + id.x) * pc.channel_count;
    for (uint ch = 0u; ch < pc.channel_count; ch++) {
        uint kind = pc.kind[ch], seed = pc.seed[ch];
        int a = int(pc.a[ch]), b = int(pc.b[ch]), c = int(pc.c[ch]);
        precise float v;
        if (kind == SB_NOISE_PERLIN_WORLEY) {
            precise float w = noise_worley_fbm(p, c, seed + 100u);
            v = w + noise_perlin_fbm(p, a, b, seed) * (1.0 - w);
        } else if (kind == SB_NOISE_WORLEY_FBM) {
            v = noise_worley_fbm(p, a, seed);
        } else if (kind == SB_NOISE_PERLIN_FBM) {
            precise float stretched = 0.5 + (noise_perlin_fbm(p, a, b, seed) - 0.5) * float(1u << uint(c));
            v = clamp(stretched, 0.0, 1.0);
        } else {
            v = curl(p, a, b, seed, uint(c));
        }
        result[base + ch] = v;
    }
}
