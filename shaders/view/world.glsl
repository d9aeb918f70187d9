/* The world's vertices, pulled by gl_VertexIndex (no vertex input state). */
#ifndef SB_WORLD_GLSL
#define SB_WORLD_GLSL

#include "view_gpu.h"
#include "frame.glsl"

layout(std430, set = 0, binding = SB_VIEW_BINDING_VERTICES) readonly buffer VertexBuffer {
    sb_vertex_gpu vertices[];
};

/* A vertex relative to the camera (m): the frame's matrices take offsets
 * from the camera, so fp32 keeps millimetres tens of kilometres out. */
vec3 vertex_offset(sb_vertex_gpu v)
{
    return v.position.xyz - frame.camera_m.xyz;
}

#endif
