#version 450
// A reflection probe's cube, level 0 (config.h, sb_capture_push): per
// texel, a ray from the probe through the BVH. Rays that leave the world
// see the sky (sky_radiance: single scattering with the baked sun
// transmittance, multiple scattering, the lit planet below the horizon;
// the sun's disk is left out, a runtime adds it analytically). Rays that
// hit a surface see it Lambertian (its albedo textured: surface.glsl): albedo / pi times the sun's irradiance
// through the atmosphere (the transmittance LUT at the point's altitude,
// a shadow ray) plus the sky's: its order-2 SH radiance L_k times the
// point's transfer T_k, the SH of the clamped cosine over the directions
// of a spherical Fibonacci set that escape (nothing where blocked: one
// bounce), clamped at zero. w flags a back face: a probe inside geometry.
// The surfaces buffer gets what a runtime relights the texel from
// (config.h, SB_CAPTURE_BINDING_SURFACES_OUT): albedo, distance, normal,
// transfer. In passes of SB_CAPTURE_PASS_DIRECTIONS of the sphere set
// (config.h), the transfer added in a fixed order, the sky's light in the
// last.
#extension GL_GOOGLE_include_directive : require
#include "config.h"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;

#define SB_SUN_TRANSMITTANCE_LUT
#include "atmosphere.glsl"
#include "sky_radiance.glsl"

layout(std430, binding = SB_CAPTURE_BINDING_OUT) buffer Out { vec4 radiance[]; };
layout(std430, binding = SB_CAPTURE_BINDING_NODES) readonly buffer Nodes { vec4 bvh_nodes[]; };
layout(std430, binding = SB_CAPTURE_BINDING_TRIANGLES) readonly buffer Triangles { vec4 bvh_triangles[]; };
layout(std430, binding = SB_CAPTURE_BINDING_SKY_SH) readonly buffer SkySh { vec4 sky_sh[SB_PROBE_SH]; };
layout(std430, binding = SB_CAPTURE_BINDING_SURFACES_OUT) buffer Surfaces { vec4 surfaces[]; };
layout(push_constant) uniform Push { sb_capture_push pc; };

#define BVH_HIT_SLOT
#include "bvh.glsl"
#include "cube.glsl"
#include "sh.glsl"
#define SURFACE_BINDING SB_CAPTURE_BINDING_SURFACE
#include "surface.glsl"
#include "relight.glsl"

vec3 sky(float h, vec3 d)
{
    vec3 s = pc.sun_direction.xyz;
    return sky_radiance(h, clamp(d.y, -1.0, 1.0), clamp(s.y, -1.0, 1.0), clamp(dot(d, s), -1.0, 1.0));
}

/* The hit's albedo and normal (toward the probe), its sun irradiance (in
 * the first pass) and this pass's share of its transfer. */
void surface(vec3 origin, vec3 d, BvhHit hit, out vec3 rho, out vec3 n, out vec3 e_sun, out float t[SB_PROBE_SH])
{
    vec4 e1 = bvh_triangles[3 * hit.slot + 1], e2 = bvh_triangles[3 * hit.slot + 2];
    n = normalize(bvh_world_normal(cross(e1.xyz, e2.xyz), hit.instance));
    if (dot(n, d) > 0.0)
        n = -n; // the side the probe sees
    // a texel's cone: 2 / n radians across at a face's centre
    rho = surface_albedo(hit, hit.t * 2.0 / float(pc.face_size), abs(dot(n, d)));
    vec3 x = origin + d * hit.t;
    float eps = relight_lift(x);
    vec3 from = x + n * eps;
    uint first = pc.first_direction, sphere = 2u * pc.ambient_rays;
    e_sun = first == 0u ? relight_light(x, n, relight_altitude(origin, x), pc.sun_direction.xyz) : vec3(0.0);
    for (int k = 0; k < SB_PROBE_SH; k++)
        t[k] = 0.0;
    for (uint i = first; i < min(first + SB_CAPTURE_PASS_DIRECTIONS, sphere); i++) {
        vec3 l = probe_direction(i, sphere);
        float c = dot(n, l);
        if (c <= 0.0 || bvh_trace(from, l, eps, 1e30, true).triangle != SB_BVH_MISS)
            continue;
        float y[SB_PROBE_SH];
        sh9_basis(l, y);
        for (int k = 0; k < SB_PROBE_SH; k++)
            t[k] += c * y[k];
    }
    for (int k = 0; k < SB_PROBE_SH; k++)
        t[k] *= 12.566370614359172 / float(sphere);
}

void main()
{
    uvec2 t = gl_GlobalInvocationID.xy;
    uint n = pc.face_size;
    if (t.x >= n || t.y >= 6u * n)
        return;
    uint texel = t.y * n + t.x;
    uint face = t.y / n;
    vec2 uv = (vec2(t.x, t.y - face * n) + 0.5) / float(n) * 2.0 - 1.0;
    vec3 d = normalize(cube_direction(face, uv));
    vec3 origin = pc.origin_m.xyz;
    float h = clamp(pc.origin_m.w, 0.0, atmosphere_thickness());
    BvhHit hit;
    hit.triangle = SB_BVH_MISS;
    if (pc.has_world != 0u)
        hit = bvh_trace(origin, d, pc.tmin_m, 1e30, false);
    bool last = pc.first_direction + SB_CAPTURE_PASS_DIRECTIONS >= 2u * pc.ambient_rays;
    if (hit.triangle == SB_BVH_MISS) {
        if (pc.first_direction == 0u) {
            radiance[texel] = vec4(sky(h, d), 0.0);
            for (uint k = 0u; k < SB_RELIGHT_VEC4S; k++)
                surfaces[SB_RELIGHT_VEC4S * texel + k] = vec4(0.0);
        }
        return;
    }
    vec3 rho, normal, e_sun;
    float transfer[SB_PROBE_SH];
    surface(origin, d, hit, rho, normal, e_sun, transfer);
    uint at = SB_RELIGHT_VEC4S * texel;
    vec4 t0 = vec4(transfer[0], transfer[1], transfer[2], transfer[3]);
    vec4 t1 = vec4(transfer[4], transfer[5], transfer[6], transfer[7]);
    float t8 = transfer[8];
    vec4 lit = vec4(rho / PI * e_sun, (hit.triangle & SB_BVH_BACK_FACE) != 0u ? 1.0 : 0.0);
    if (pc.accumulate != 0u) { // a pass (config.h) adds its slice of the transfer to the passes' before
        t0 += vec4(surfaces[at + 1u].w, surfaces[at + 2u].xyz);
        t1 += vec4(surfaces[at + 2u].w, surfaces[at + 3u].xyz);
        t8 += surfaces[at + 3u].w;
        lit.rgb = radiance[texel].rgb;
    }
    surfaces[at] = vec4(rho, hit.t);
    surfaces[at + 1u] = vec4(normal, t0.x);
    surfaces[at + 2u] = vec4(t0.yzw, t1.x);
    surfaces[at + 3u] = vec4(t1.yzw, t8);
    if (last) // the sky's light through the whole transfer
        lit.rgb += rho / PI * relight_sky(float[SB_PROBE_SH](t0.x, t0.y, t0.z, t0.w, t1.x, t1.y, t1.z, t1.w, t8));
    radiance[texel] = lit;
}
