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

#ifdef SB_INSTANCED
/* An instanced world (runtime/world.h): the vertices in their mesh's
 * space, placed by sb_instance_gpu records. */
layout(std430, set = 0, binding = SB_VIEW_BINDING_INSTANCES) readonly buffer InstanceBuffer {
    sb_instance_gpu instances[];
};

/* The raster draws': the instance drawn as gl_InstanceIndex, from the
 * frame's cull (runtime/renderer.c). */
layout(std430, set = 0, binding = SB_VIEW_BINDING_VISIBLE) readonly buffer VisibleBuffer {
    uint visible_instances[];
};

vec3 instance_point(uint i, vec3 p)
{
    vec4 h = vec4(p, 1.0);
    return vec3(dot(instances[i].to_world[0], h), dot(instances[i].to_world[1], h), dot(instances[i].to_world[2], h));
}

vec3 instance_direction(uint i, vec3 d)
{
    return vec3(dot(instances[i].to_world[0].xyz, d), dot(instances[i].to_world[1].xyz, d),
                dot(instances[i].to_world[2].xyz, d));
}

vec3 instance_normal(uint i, vec3 n)
{
    return vec3(dot(instances[i].normal[0].xyz, n), dot(instances[i].normal[1].xyz, n),
                dot(instances[i].normal[2].xyz, n));
}
#endif

#endif
