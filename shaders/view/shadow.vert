#version 450
/* Depth of the world from the sun, into one cascade (pc.cascade); with
 * SB_INSTANCED, of instance visible_instances[gl_InstanceIndex] of an instanced
 * world's mesh. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"

#include "frame.glsl"
layout(push_constant) uniform ViewPush {
    sb_view_push pc;
};
#include "world.glsl"

void main()
{
    sb_vertex_gpu v = vertices[gl_VertexIndex];
#ifdef SB_INSTANCED
    vec3 offset = instance_point(visible_instances[gl_InstanceIndex], v.position.xyz) - frame.camera_m.xyz;
#else
    vec3 offset = vertex_offset(v);
#endif
    mat4 m = pc.cascade < SB_CASCADES ? frame.shadow_view_proj[pc.cascade] : frame.far_view_proj; /* the far map */
    gl_Position = m * vec4(offset, 1.0);
}
