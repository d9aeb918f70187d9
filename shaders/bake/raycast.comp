#version 450
#extension GL_GOOGLE_include_directive : require
// Cast a list of rays against a BVH (the tests' and bench's check against
// Embree): one invocation a ray, closest or any hit.
#include "config.h"

layout(local_size_x = SB_RAYCAST_WORKGROUP) in;
layout(std430, binding = SB_RAYCAST_BINDING_NODES) readonly buffer Nodes { vec4 bvh_nodes[]; };
layout(std430, binding = SB_RAYCAST_BINDING_TRIANGLES) readonly buffer Triangles { vec4 bvh_triangles[]; };
layout(std430, binding = SB_RAYCAST_BINDING_RAYS) readonly buffer Rays { vec4 rays[]; };
layout(std430, binding = SB_RAYCAST_BINDING_HITS) writeonly buffer Hits { vec4 hits[]; };
layout(push_constant) uniform Push { sb_raycast_push pc; };

#include "bvh.glsl"

void main()
{
    uint i = pc.first + gl_GlobalInvocationID.x;
    if (i >= pc.ray_count)
        return;
    vec4 a = rays[2 * i], b = rays[2 * i + 1];
    BvhHit hit = bvh_trace(a.xyz, b.xyz, a.w, b.w, pc.any_hit != 0u);
#ifdef BVH_INSTANCES
    uint instance = hit.instance == SB_BVH_NO_INSTANCE ? hit.instance : floatBitsToUint(bvh_nodes[2 * hit.instance + 3].y);
#else
    uint instance = SB_BVH_NO_INSTANCE;
#endif
    hits[i] = vec4(hit.t, uintBitsToFloat(hit.triangle), uintBitsToFloat(instance), 0.0);
}
