#version 450
/* The world seen from the camera; with SB_INSTANCED, instance
 * gl_InstanceIndex of an instanced world's mesh. */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"

#include "frame.glsl"
#include "world.glsl"

layout(location = 0) out vec3 out_offset; /* from the camera, m */
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec3 out_albedo;
layout(location = 3) out vec2 out_metallic_roughness;
layout(location = 4) out vec2 out_uv;
layout(location = 5) flat out vec2 out_images; /* the base colour's and metallic-roughness's texture + 1 */
layout(location = 6) out vec3 out_tangent;
layout(location = 7) flat out float out_normal_map; /* +-(the normal map's texture + 1) */
layout(location = 8) flat out float out_emission;   /* the emission's record + 1 (0: none) */

void main()
{
    sb_vertex_gpu v = vertices[gl_VertexIndex];
#ifdef SB_INSTANCED
    out_offset = instance_point(visible_instances[gl_InstanceIndex], v.position.xyz) - frame.camera_m.xyz;
    out_normal = normalize(instance_normal(visible_instances[gl_InstanceIndex], v.normal.xyz));
    out_tangent = instance_direction(visible_instances[gl_InstanceIndex], v.tangent.xyz);
#else
    out_offset = vertex_offset(v);
    out_normal = v.normal.xyz;
    out_tangent = v.tangent.xyz;
#endif
    out_albedo = v.albedo.rgb;
    out_metallic_roughness = vec2(v.position.w, v.normal.w);
    out_uv = v.uv.xy;
    out_images = v.uv.zw;
    out_normal_map = v.tangent.w;
    out_emission = v.albedo.w;
    gl_Position = frame.view_proj * vec4(out_offset, 1.0);
}
