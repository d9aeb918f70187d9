#version 450
// The detail probes' sight masks (config.h's SB_PROBE_SIGHT_*): a workgroup
// a probe casts the segment from the probe to each sample point of the
// cube of cells around its lattice point, stopping at the first hit, and
// sets the bit of each one that meets nothing. Bits are ORed into
// workgroup memory (order-free), so a mask is the same on every run.
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#if SB_PROBE_SIGHT_SIDE != 8
#error "the bit index below is (k 8 + j) 8 + i"
#endif

layout(local_size_x = SB_PROBE_THREADS) in;
layout(std430, binding = SB_RAYCAST_BINDING_NODES) readonly buffer Nodes { vec4 bvh_nodes[]; };
layout(std430, binding = SB_RAYCAST_BINDING_TRIANGLES) readonly buffer Triangles { vec4 bvh_triangles[]; };
layout(std430, binding = SB_RAYCAST_BINDING_RAYS) readonly buffer Probes { vec4 probes[]; };
layout(std430, binding = SB_RAYCAST_BINDING_HITS) writeonly buffer Out { uint words[]; };
layout(push_constant) uniform Push { sb_probe_sight_push pc; };

#include "bvh.glsl"

shared uint mask[SB_PROBE_SIGHT_WORDS];

void main()
{
    uint probe = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
    uint lane = gl_LocalInvocationID.x;
    if (probe >= pc.probe_count)
        return; // whole workgroups only: no barrier is skipped by part of one
    if (lane < SB_PROBE_SIGHT_WORDS)
        mask[lane] = 0u;
    barrier();
    vec3 origin = probes[2 * probe].xyz, lattice = probes[2 * probe + 1].xyz;
    for (uint b = lane; b < SB_PROBE_SIGHT_SAMPLES; b += SB_PROBE_THREADS) {
        uvec3 ijk = uvec3(b & 7u, (b >> 3) & 7u, b >> 6);
        vec3 target = lattice + ((vec3(ijk) + 0.5) * (2.0 / float(SB_PROBE_SIGHT_SIDE)) - 1.0) * pc.spacing_m;
        vec3 to = target - origin;
        float len = length(to);
        bool seen = len <= pc.tmin_m;
        if (!seen)
            seen = bvh_trace(origin, to / len, pc.tmin_m, len, true).triangle == SB_BVH_MISS;
        if (seen)
            atomicOr(mask[b >> 5], 1u << (b & 31u));
    }
    barrier();
    if (lane < SB_PROBE_SIGHT_WORDS)
        words[probe * SB_PROBE_SIGHT_WORDS + lane] = mask[lane];
}
