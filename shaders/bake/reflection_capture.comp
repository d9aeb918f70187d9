#version 450
// A reflection probe's cube, level 0 (config.h, sb_capture_push): per
// texel, a ray from the probe through the BVH. Rays that leave the world
// see the sky (sky_radiance: single scattering with the baked sun
// transmittance, multiple scattering, the lit planet below the horizon;
// the sun's disk is left out, a runtime adds it analytically). Rays that
// hit a surface see it Lambertian (its albedo textured: surface.glsl): albedo / pi times the sun's irradiance
// through the atmosphere (the transmittance LUT at the point's altitude,
// a shadow ray) plus the sky's, over a spherical Fibonacci set from the
// point (the sky's order-2 SH where a ray escapes, nothing where it is
// blocked: one bounce). w flags a back face: a probe inside geometry.
// In passes of SB_CAPTURE_PASS_DIRECTIONS of the sphere set (config.h),
// added in a fixed order.
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
layout(push_constant) uniform Push { sb_capture_push pc; };

#define BVH_HIT_SLOT
#include "bvh.glsl"
#include "cube.glsl"
#include "sh.glsl"
#define SURFACE_BINDING SB_CAPTURE_BINDING_SURFACE
#include "surface.glsl"

vec3 sky(float h, vec3 d)
{
    vec3 s = pc.sun_direction.xyz;
    return sky_radiance(h, clamp(d.y, -1.0, 1.0), clamp(s.y, -1.0, 1.0), clamp(dot(d, s), -1.0, 1.0));
}

vec3 surface(vec3 origin, vec3 d, BvhHit hit)
{
    vec4 e1 = bvh_triangles[3 * hit.slot + 1], e2 = bvh_triangles[3 * hit.slot + 2];
    vec3 n = normalize(bvh_world_normal(cross(e1.xyz, e2.xyz), hit.instance));
    if (dot(n, d) > 0.0)
        n = -n; // the side the probe sees
    // a texel's cone: 2 / n radians across at a face's centre
    vec3 rho = surface_albedo(hit, hit.t * 2.0 / float(pc.face_size), abs(dot(n, d)));
    vec3 x = origin + d * hit.t;
    float eps = 1e-4 + 2e-6 * max(abs(x.x), max(abs(x.y), abs(x.z)));
    vec3 from = x + n * eps;
    vec3 s = pc.sun_direction.xyz;
    float h = clamp(pc.origin_m.w + (x.y - origin.y) * 1e-3, 0.0, atmosphere_thickness());
    vec3 E = vec3(0.0);
    float ns = dot(n, s);
    uint first = pc.first_direction, sphere = 2u * pc.ambient_rays;
    if (first == 0u && ns > 0.0 && bvh_trace(from, s, eps, 1e30, true).triangle == SB_BVH_MISS)
        E += atm.solar_irradiance.rgb * sun_transmittance(h, clamp(s.y, -1.0, 1.0)) * ns;
    vec3 sky_E = vec3(0.0);
    for (uint i = first; i < min(first + SB_CAPTURE_PASS_DIRECTIONS, sphere); i++) {
        vec3 l = probe_direction(i, sphere);
        float c = dot(n, l);
        if (c <= 0.0 || bvh_trace(from, l, eps, 1e30, true).triangle != SB_BVH_MISS)
            continue;
        float y[SB_PROBE_SH];
        sh9_basis(l, y);
        vec3 L = vec3(0.0);
        for (int k = 0; k < SB_PROBE_SH; k++)
            L += sky_sh[k].rgb * y[k];
        sky_E += c * max(L, vec3(0.0));
    }
    E += sky_E * (12.566370614359172 / float(sphere));
    return rho / PI * E;
}

void main()
{
    uvec2 t = gl_GlobalInvocationID.xy;
    uint n = pc.face_size;
    if (t.x >= n || t.y >= 6u * n)
        return;
    uint face = t.y / n;
    vec2 uv = (vec2(t.x, t.y - face * n) + 0.5) / float(n) * 2.0 - 1.0;
    vec3 d = normalize(cube_direction(face, uv));
    vec3 origin = pc.origin_m.xyz;
    float h = clamp(pc.origin_m.w, 0.0, atmosphere_thickness());
    vec4 out_value;
    BvhHit hit;
    hit.triangle = SB_BVH_MISS;
    if (pc.has_world != 0u)
        hit = bvh_trace(origin, d, pc.tmin_m, 1e30, false);
    if (hit.triangle == SB_BVH_MISS)
        out_value = vec4(pc.first_direction == 0u ? sky(h, d) : vec3(0.0), 0.0);
    else
        out_value = vec4(surface(origin, d, hit), (hit.triangle & SB_BVH_BACK_FACE) != 0u ? 1.0 : 0.0);
    // a pass (config.h) adds its slice of the ambient light to the passes' before
    if (pc.accumulate != 0u)
        out_value.rgb += radiance[t.y * n + t.x].rgb;
    radiance[t.y * n + t.x] = out_value;
}
