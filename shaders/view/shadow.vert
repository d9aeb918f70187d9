#version 450
/* Depth of the world from the sun, into one cascade (pc.cascade). */
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
    gl_Position = frame.shadow_view_proj[pc.cascade] * vec4(vertex_offset(v), 1.0);
}
