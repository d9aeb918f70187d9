#version 450
/* A reflection cube's level 0 relit for this frame's lights
 * (runtime/passes/reflections.c), cube `pc.item`, a texel an
 * invocation, from the pack's reflection_surfaces as the bake lit it
 * (bake/reflection_capture.comp):
 * - a texel whose ray left the world sees the sky: sky_light.glsl's
 *   radiance toward it (the sky-view LUT, every light in the sky);
 * - a surface is Lambertian: albedo / pi times, for each light in the sky,
 *   its irradiance through the transmittance LUT at the point's altitude
 *   and a shadow ray through the world's BVH, plus the sky's irradiance,
 *   the texel's transfer times the sky's order-2 SH (probe_sky.comp's),
 *   clamped at zero.
 * Into the cube's level 0 and level 0 of the chain the prefilter reads. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "probes_gpu.h"
#include "view.glsl"
#include "sky_light.glsl"
#define REFLECTION_CUBES_WRITABLE
#include "reflections.glsl"

layout(local_size_x = SB_RELIGHT_THREADS) in;
layout(std430, set = 0, binding = SB_VIEW_BINDING_PROBE_LIGHT) readonly buffer ProbeLightBuffer {
    vec4 sky_sh[SB_PROBE_SH]; /* rgb: the sky's radiance (probes.glsl) */
};
layout(std430, set = 0, binding = SB_VIEW_BINDING_REFLECTION_SURFACES) readonly buffer Surfaces {
    vec4 surfaces[]; /* cube by cube, level 0 (config.h, SB_RELIGHT_VEC4S) */
};
layout(std430, set = 0, binding = SB_VIEW_BINDING_REFLECTION_CHAIN) writeonly buffer Chain { vec4 chain[]; };
layout(std430, set = 0, binding = SB_VIEW_BINDING_BVH_NODES) readonly buffer BvhNodes { vec4 bvh_nodes[]; };
layout(std430, set = 0, binding = SB_VIEW_BINDING_BVH_TRIANGLES) readonly buffer BvhTriangles { vec4 bvh_triangles[]; };
#define BVH_ANY_HIT_MATERIAL_0_PASSES /* receivers only (a ground) cast no shadow, as in the scene */
#include "bvh.glsl"
#include "relight.glsl"

void main()
{
    uint n = reflections.info.x, texel = gl_GlobalInvocationID.x, cube = pc.item;
    if (texel >= 6u * n * n)
        return;
    uint face = texel / (n * n), in_face = texel - face * n * n;
    vec2 uv = (vec2(in_face % n, in_face / n) + 0.5) / float(n) * 2.0 - 1.0;
    vec3 d = normalize(cube_direction(face, uv));
    uint at = SB_RELIGHT_VEC4S * (cube * 6u * n * n + texel);
    vec4 g0 = surfaces[at], g1 = surfaces[at + 1u], g2 = surfaces[at + 2u], g3 = surfaces[at + 3u];
    vec3 L;
    if (g0.w <= 0.0) {
        L = sky_light_radiance(d);
    } else {
        vec3 probe = reflection_data[3u * cube].xyz, x = probe + d * g0.w;
        vec3 e = relight_sky(float[SB_PROBE_SH](g1.w, g2.x, g2.y, g2.z, g2.w, g3.x, g3.y, g3.z, g3.w));
        float h = relight_altitude(probe, x);
        for (int i = 0; i < sky_light_count(); i++)
            e += light_color(i) * relight_light(x, g1.xyz, h, light_direction(i));
        L = g0.rgb / PI * e;
    }
    cube_texels[cube * reflections.level_offsets[3].w + texel] = vec4(L, 0.0);
    chain[texel] = vec4(L, 0.0);
}
