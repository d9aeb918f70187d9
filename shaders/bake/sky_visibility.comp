#version 450
// Sky visibility at probes: every ray that escapes the geometry (misses
// every triangle within tmax) adds the SH basis of its direction, weighted
// 4 pi / n; rays that hit count back faces (a probe inside geometry sees
// mostly back faces) and their distances. One workgroup a probe, in passes
// of SB_VISIBILITY_PASS_RAYS rays (config.h); the partial sums are added
// in a fixed tree order and the passes in a fixed order, so results do
// not depend on scheduling.
#extension GL_GOOGLE_include_directive : require
#include "config.h"

layout(local_size_x = SB_PROBE_THREADS) in;
layout(std430, binding = SB_RAYCAST_BINDING_NODES) readonly buffer Nodes { vec4 bvh_nodes[]; };
layout(std430, binding = SB_RAYCAST_BINDING_TRIANGLES) readonly buffer Triangles { vec4 bvh_triangles[]; };
layout(std430, binding = SB_RAYCAST_BINDING_RAYS) readonly buffer Probes { vec4 probes[]; };
layout(std430, binding = SB_RAYCAST_BINDING_HITS) buffer Out { float results[]; };
layout(std430, binding = SB_PROBE_BINDING_ORDER) readonly buffer Order { uint order[]; };
layout(push_constant) uniform Push { sb_probe_push pc; };

#include "bvh.glsl"
#include "sh.glsl"

#define SUMS (SB_PROBE_SH + 3)
shared float partial[SUMS][SB_PROBE_THREADS];

void main()
{
    bvh_reach = pc.tmax_m; // placed objects past it are not met (a tiled bake's reach)
    uint probe = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
    uint lane = gl_LocalInvocationID.x;
    if (probe >= pc.probe_count)
        return; // whole workgroups only: no barrier is skipped by part of one
    vec3 origin = probes[probe].xyz;
    float sums[SUMS];
    for (int k = 0; k < SUMS; k++)
        sums[k] = 0.0;
    // Neighbouring invocations cast neighbouring directions (order[] is
    // sorted along a space-filling curve): they traverse the same nodes.
    uint end = min(pc.first_ray + SB_VISIBILITY_PASS_RAYS, pc.ray_count);
    for (uint k = pc.first_ray + lane; k < end; k += SB_PROBE_THREADS) {
        vec3 d = probe_direction(order[k], pc.ray_count);
        BvhHit hit = bvh_trace(origin, d, pc.tmin_m, 1e30, false);
        if (hit.triangle == SB_BVH_MISS) {
            float y[SB_PROBE_SH];
            sh9_basis(d, y);
            for (int k = 0; k < SB_PROBE_SH; k++)
                sums[k] += y[k];
        } else {
            sums[SB_PROBE_SH] += (hit.triangle & SB_BVH_BACK_FACE) != 0u ? 1.0 : 0.0;
            sums[SB_PROBE_SH + 1] += 1.0;
            sums[SB_PROBE_SH + 2] += hit.t;
        }
    }
    for (int k = 0; k < SUMS; k++)
        partial[k][lane] = sums[k];
    barrier();
    for (uint stride = SB_PROBE_THREADS / 2; stride > 0; stride /= 2) {
        if (lane < stride)
            for (int k = 0; k < SUMS; k++)
                partial[k][lane] += partial[k][lane + stride];
        barrier();
    }
    if (lane == 0) {
        uint base = probe * SB_VISIBILITY_FLOATS; // the passes' sums so far, then the record
        float total[SUMS];
        for (int k = 0; k < SUMS; k++)
            total[k] = partial[k][0] + (pc.accumulate != 0u ? results[base + k] : 0.0);
        if (pc.last == 0u) {
            for (int k = 0; k < SUMS; k++)
                results[base + k] = total[k];
        } else {
            float n = float(pc.ray_count), hits = total[SB_PROBE_SH + 1];
            for (int k = 0; k < SB_PROBE_SH; k++)
                results[base + k] = total[k] * (12.566370614359172 / n);
            results[base + SB_PROBE_SH] = hits > 0.0 ? total[SB_PROBE_SH] / n : 0.0;
            results[base + SB_PROBE_SH + 1] = hits / n;
            results[base + SB_PROBE_SH + 2] = hits > 0.0 ? total[SB_PROBE_SH + 2] / hits : 0.0;
        }
    }
}
