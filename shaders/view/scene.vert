#version 450
/* The world seen from the camera. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"

#include "frame.glsl"
#include "world.glsl"

layout(location = 0) out vec3 out_offset; /* from the camera, m */
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec3 out_albedo;
layout(location = 3) out vec2 out_metallic_roughness;

void main()
{
    sb_vertex_gpu v = vertices[gl_VertexIndex];
    out_offset = vertex_offset(v);
    out_normal = v.normal.xyz;
    out_albedo = v.albedo.rgb;
    out_metallic_roughness = vec2(v.position.w, v.normal.w);
    gl_Position = frame.view_proj * vec4(out_offset, 1.0);
}
