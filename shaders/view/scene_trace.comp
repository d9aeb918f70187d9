#version 450
/* The world traced: one ray a pixel through the world's BVH (bvh.glsl)
 * from the camera through the pixel's centre, where the rasteriser samples
 * too, lit by scene_shading.glsl with a shadow ray for the key light's
 * visibility (shadows.glsl, SB_TRACED_SHADOWS), toward a new point of its
 * disk each frame, their mean kept over frames (soft_sun). It writes what the raster scene pass
 * writes: the lit radiance, zero where no triangle is hit (the sky pass
 * fills those), and the depth as the rasteriser's reverse-Z projection
 * would (0 for the sky). For GPUs whose rasteriser is their weak part
 * (runtime/passes/scene.c). Built with SB_AERIAL_VOLUME_ONLY too, as
 * scene.frag is, and for an instanced world with SB_INSTANCED and
 * BVH_INSTANCES (its BVH's two levels, its vertices placed by instances). */
#extension GL_GOOGLE_include_directive : require
#include "view_gpu.h"
#include "scene_shading.glsl"
#include "shadows.glsl"
#include "world.glsl"
#include "material.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(set = 0, binding = SB_VIEW_BINDING_HDR, rgba16f) uniform writeonly image2D hdr;
layout(set = 0, binding = SB_VIEW_BINDING_DEPTH_OUT, r32f) uniform writeonly image2D depth_out;
layout(set = 0, binding = SB_VIEW_BINDING_SUN_HISTORY, rgba16f) uniform readonly image2D sun_history;
layout(set = 0, binding = SB_VIEW_BINDING_SUN_HISTORY_OUT, rgba16f) uniform writeonly image2D sun_history_out;
layout(std430, set = 0, binding = SB_VIEW_BINDING_SCENE_HISTORY) readonly buffer SceneHistory {
    sb_scene_history_gpu history;
};

/*
 * The key light's visibility with its penumbra: this frame's ray toward a
 * point of the light's disk, averaged with the rays of the frames before
 * that saw the same point (reprojected into the last frame, and the
 * distance it kept there within 1%), at most SB_SUN_RAYS of them. A point
 * seen anew starts from the disk's centre: its first frame is the hard
 * shadow, exact; the points over the disk follow in Vogel's spiral, turned
 * by a per-pixel noise, and once SB_SUN_RAYS are kept each frame replaces
 * the oldest in the mean's weight.
 */
float soft_sun(ivec2 pixel, vec3 offset, vec3 n)
{
    float distance_m = length(offset);
    float mean = 0.0, kept = 0.0;
    vec3 before = offset + history.camera_motion_m.xyz;
    vec4 clip = history.previous_view_proj * vec4(before, 1.0);
    if (history.camera_motion_m.w != 0.0 && clip.w > 0.0) {
        ivec2 q = ivec2(floor((clip.xy / clip.w * 0.5 + 0.5) * vec2(frame.size.xy)));
        if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, ivec2(frame.size.xy)))) {
            vec4 h = imageLoad(sun_history, q);
            float was = length(before);
            if (abs(h.z - was) <= 0.01 * was) {
                mean = h.x;
                kept = h.y;
            }
        }
    }
    float v = 0.0;
    if (dot(n, key_direction()) > 0.0) { /* a face turned from the light gets none of it */
        int k = kept < float(SB_SUN_RAYS) ? int(kept) : 1 + int(history.frame.x % uint(SB_SUN_RAYS - 1));
        v = disk_visibility(offset, n, k, SB_SUN_RAYS, pixel_turn(vec2(pixel)));
    }
    kept = min(kept + 1.0, float(SB_SUN_RAYS));
    mean += (v - mean) / kept;
    imageStore(sun_history_out, pixel, vec4(mean, kept, distance_m, 0.0));
    return mean;
}

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy)))
        return;
    vec2 uv = (vec2(pixel) + 0.5) / vec2(frame.size.xy);
    vec3 d = view_ray(uv);
    /* from the near plane on, as the rasteriser clips */
    float t_near = frame.camera_m.w / max(dot(d, frame.camera_forward.xyz), 1e-6);
    BvhHit hit = bvh_trace(frame.camera_m.xyz, d, t_near, 1e30, false);
    if (hit.triangle == SB_BVH_MISS) {
        imageStore(hdr, pixel, vec4(0.0));
        imageStore(depth_out, pixel, vec4(0.0));
        imageStore(sun_history_out, pixel, vec4(0.0, 0.0, -1.0, 0.0));
        return;
    }
    sb_vertex_gpu v = vertices[3u * (hit.triangle & ~SB_BVH_BACK_FACE)];
    vec3 offset = d * hit.t;
#ifdef SB_INSTANCED
    /* the instance the BVH's record names (bvh.h), its normals' matrix */
    uint instance = hit.instance == SB_BVH_NO_INSTANCE ? 0u : floatBitsToUint(bvh_nodes[2u * hit.instance + 3u].y);
    vec3 n = normalize(instance_normal(instance, v.normal.xyz));
#else
    vec3 n = v.normal.xyz;
#endif
    vec4 clip = frame.view_proj * vec4(offset, 1.0);
    imageStore(depth_out, pixel, vec4(clip.z / clip.w));
    float visibility = soft_sun(pixel, offset, n);
    vec3 albedo = v.albedo.rgb, shading_n = n;
    vec2 metallic_roughness = vec2(v.position.w, v.normal.w);
    vec3 emitted = vec3(0.0);
    if (v.uv.zw != vec2(0.0) || v.tangent.w != 0.0 || v.albedo.w != 0.0) {
        uint first = 3u * (hit.triangle & ~SB_BVH_BACK_FACE);
        sb_vertex_gpu b = vertices[first + 1u], c = vertices[first + 2u];
        vec3 w = vec3(1.0 - hit.uv.x - hit.uv.y, hit.uv);
        vec2 tex = w.x * v.uv.xy + w.y * b.uv.xy + w.z * c.uv.xy;
        vec3 tangent = w.x * v.tangent.xyz + w.y * b.tangent.xyz + w.z * c.tangent.xyz;
        vec3 pa = v.position.xyz, pb = b.position.xyz, pc = c.position.xyz;
#ifdef SB_INSTANCED
        tangent = instance_direction(instance, tangent);
        pa = instance_point(instance, pa);
        pb = instance_point(instance, pb);
        pc = instance_point(instance, pc);
#endif
        /* the pixel's ray cone (its angle the pixel's) met the surface: its
         * width over the cosine, in texture coordinates by the triangle's
         * texture area over its area */
        vec2 du = b.uv.xy - v.uv.xy, dv = c.uv.xy - v.uv.xy;
        float area_uv = abs(du.x * dv.y - du.y * dv.x);
        float area_m = length(cross(pb - pa, pc - pa));
        float pixel = length(view_ray(uv + vec2(0.0, 1.0 / float(frame.size.y))) - d); /* radians a pixel */
        float width_m = hit.t * pixel / max(abs(dot(d, n)), 0.05);
        float footprint = width_m * sqrt(area_uv / max(area_m, 1e-20));
        material_textures(tex, footprint, v.uv.zw, vec4(tangent, v.tangent.w), albedo, metallic_roughness,
                          shading_n);
        emitted = material_emitted(v.albedo.w, tex, footprint);
    }
    vec3 key_part; /* the traced shadows are exact: no contact shadows */
    imageStore(hdr, pixel, scene_shade(offset, shading_n, n, albedo, metallic_roughness, emitted, uv, visibility, key_part));
}
