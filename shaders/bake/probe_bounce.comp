#version 450
// The one-bounce transfer at probes (config.h, sb_bounce_push): for each
// of a probe's rays that hits a surface (albedo rho, textured at the ray
// cone's footprint: surface.glsl; normal n turned toward
// the probe), the order-2 SH g_k of (n.l) V(l) over the directions l that
// leave the surface (V: 1 where a ray from the hit escapes the geometry),
// by a spherical Fibonacci set of 2 x secondary directions of which the
// surface's side is cast; summed as B[m][k] += 4 pi / n Y_m(w) rho / pi g_k
// over the probe's rays w. A runtime relights it for any environment L and
// sun: the radiance bounced toward the probe from w is sum_k B[m][k] L_k
// (and E_sun sum_k B[m][k] Y_k(sun)) in the order-1 SH of w. With it, the
// operator of the next bounces (config.h): M[m][j] += 4 pi / n Y_m(w)
// rho / pi A_j Y_j(n), the irradiance at the hit of an order-1 radiance
// b_j (A_j the clamped cosine's pi, 2 pi / 3) sent back toward the probe.
// The sun's table (config.h, SB_SUN_SIDE), in passes of its own after the
// sphere set's: the hit's rho / pi Y_m(w) (n.s) V(s) for a direction s
// about each of the table's s_j (sun_table_sample: a tent around s_j, so
// that the table holds each direction's neighbourhood's mean, what the
// bilinear read between directions needs), V from a ray toward s.
// One workgroup a probe, in passes (config.h: a ray a thread and a slice
// of the sphere set or of the sun's directions each, added to the passes
// before); partial sums added in a fixed tree order (the sun's in ray
// order), the passes in a fixed order.
#extension GL_GOOGLE_include_directive : require
#include "config.h"

layout(local_size_x = SB_PROBE_THREADS) in;
layout(std430, binding = SB_RAYCAST_BINDING_NODES) readonly buffer Nodes { vec4 bvh_nodes[]; };
layout(std430, binding = SB_RAYCAST_BINDING_TRIANGLES) readonly buffer Triangles { vec4 bvh_triangles[]; };
layout(std430, binding = SB_RAYCAST_BINDING_RAYS) readonly buffer Probes { vec4 probes[]; };
layout(std430, binding = SB_RAYCAST_BINDING_HITS) buffer Out { float results[]; };
layout(push_constant) uniform Push { sb_bounce_push pc; };

#define BVH_HIT_SLOT
#include "bvh.glsl"
#include "sh.glsl"
#define SURFACE_BINDING SB_BOUNCE_BINDING_SURFACE
#include "surface.glsl"

shared float partial[SB_PROBE_SH * 3][SB_PROBE_THREADS];
#ifdef SUN_TABLE // the sun run's variant (its workgroup memory would cost the sky run's occupancy)
shared float sun_seen[SB_BOUNCE_SUN_GROUP][SB_PROBE_THREADS]; /* (n.s_j) V(s_j) of each ray's hit */
shared float sun_weight[SB_BOUNCE_SH * 3][SB_PROBE_THREADS];  /* rho / pi Y_m(w), rgb */

// A sun pass (first_direction past the sphere set): the table's directions
// [first, first + SB_BOUNCE_SUN_PASS) from this thread's hit, SB_BOUNCE_SUN_GROUP at a time.
void sun_pass(uint probe, uint lane, uint ray, uint first, bool hit, vec3 from, vec3 n, float eps,
              vec3 weight[SB_BOUNCE_SH])
{
    for (int m = 0; m < SB_BOUNCE_SH; m++)
        for (int c = 0; c < 3; c++)
            sun_weight[3 * m + c][lane] = weight[m][c];
    float scale = 12.566370614359172 / float(pc.ray_count);
    uint last = min(first + SB_BOUNCE_SUN_PASS, SB_SUN_DIRECTIONS);
    for (uint g = first; g < last; g += SB_BOUNCE_SUN_GROUP) {
        for (uint q = 0u; q < SB_BOUNCE_SUN_GROUP; q++) {
            float seen = 0.0;
            vec3 s = sun_table_sample(g + q, ray * uint(SB_SUN_DIRECTIONS) + g + q);
            float c = dot(n, s);
            if (hit && c > 0.0 && bvh_trace(from, s, eps, 1e30, true).triangle == SB_BVH_MISS)
                seen = c;
            sun_seen[q][lane] = seen;
        }
        barrier();
        for (uint o = lane; o < SB_BOUNCE_SUN_GROUP * SB_BOUNCE_SH * 3; o += SB_PROBE_THREADS) {
            uint q = o / uint(SB_BOUNCE_SH * 3), mc = o % uint(SB_BOUNCE_SH * 3);
            float sum = 0.0;
            for (uint r = 0u; r < SB_PROBE_THREADS; r++)
                sum += sun_seen[q][r] * sun_weight[mc][r];
            uint at = probe * pc.stride + SB_BOUNCE_KERNEL_FLOATS + (g + q) * uint(SB_BOUNCE_SH * 3) + mc;
            results[at] = (pc.accumulate != 0u ? results[at] : 0.0) + sum * scale;
        }
        barrier();
    }
}
#endif

void main()
{
    bvh_reach = pc.tmax_m; // placed objects past it are not met (a tiled bake's reach)
    uint probe = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
    uint lane = gl_LocalInvocationID.x;
    if (probe >= pc.probe_count)
        return; // whole workgroups only: no barrier is skipped by part of one
    vec3 origin = probes[probe].xyz;
    bool valid = probes[probe].w != 0.0;
    vec3 acc[SB_BOUNCE_SH][SB_PROBE_SH];
    vec3 op[SB_BOUNCE_SH][SB_BOUNCE_SH];
    for (int m = 0; m < SB_BOUNCE_SH; m++) {
        for (int k = 0; k < SB_PROBE_SH; k++)
            acc[m][k] = vec3(0.0);
        for (int j = 0; j < SB_BOUNCE_SH; j++)
            op[m][j] = vec3(0.0);
    }
    uint sphere = 2u * pc.secondary;
    float spread = sqrt(12.566370614359172 / float(pc.ray_count)); // a ray's cone, radians
    // one pass (config.h): a ray a thread, a slice of the sphere set
    uint r = pc.first_ray + lane, first = pc.first_direction;
    uint last = min(first + SB_BOUNCE_PASS_DIRECTIONS, sphere);
    bool sun = first >= sphere;
    vec3 w = probe_direction(min(r, pc.ray_count - 1u), pc.ray_count);
    vec3 sun_from = vec3(0.0), sun_n = vec3(0.0), sun_w[SB_BOUNCE_SH];
    float sun_eps = 0.0;
    for (int m = 0; m < SB_BOUNCE_SH; m++)
        sun_w[m] = vec3(0.0);
    BvhHit hit;
    hit.triangle = SB_BVH_MISS;
    if (r < pc.ray_count && valid)
        hit = bvh_trace(origin, w, pc.tmin_m, 1e30, false);
    if (hit.triangle != SB_BVH_MISS) {
        vec4 e1 = bvh_triangles[3 * hit.slot + 1], e2 = bvh_triangles[3 * hit.slot + 2];
#ifdef BVH_INSTANCES
        vec3 n = normalize(bvh_world_normal(cross(e1.xyz, e2.xyz), hit.instance));
#else
        vec3 n = normalize(cross(e1.xyz, e2.xyz));
#endif
        if (dot(n, w) > 0.0)
            n = -n; // the side the probe sees
        vec3 rho = surface_albedo(hit, hit.t * spread, abs(dot(n, w)));
        vec3 x = origin + w * hit.t;
        float eps = 1e-4 + 2e-6 * max(abs(x.x), max(abs(x.y), abs(x.z)));
        vec3 from = x + n * eps;
        // the surface's rays meet placed objects only as far from the
        // probe as twice the reach in all (a tiled bake's: a hit on a wide
        // terrain may lie past it)
        bvh_reach = max(2.0 * pc.tmax_m - hit.t, 0.0);
        float g[SB_PROBE_SH];
        for (int k = 0; k < SB_PROBE_SH; k++)
            g[k] = 0.0;
        for (uint i = first; i < last; i++) {
            vec3 l = probe_direction(i, sphere);
            float c = dot(n, l);
            if (c <= 0.0)
                continue;
            if (bvh_trace(from, l, eps, 1e30, true).triangle != SB_BVH_MISS)
                continue;
            float y[SB_PROBE_SH];
            sh9_basis(l, y);
            for (int k = 0; k < SB_PROBE_SH; k++)
                g[k] += c * y[k];
        }
        float ym[SB_PROBE_SH];
        sh9_basis(w, ym);
        if (sun) { /* what the sun's pass casts from, and the hit's weight */
            for (int m = 0; m < SB_BOUNCE_SH; m++)
                sun_w[m] = rho * (0.3183098861837907 * ym[m]);
            sun_from = from;
            sun_n = n;
            sun_eps = eps;
        }
        vec3 weight = rho * (4.0 / float(sphere)); // (rho / pi) (4 pi / 2s): g's quadrature weight and rho / pi
        for (int m = 0; m < SB_BOUNCE_SH; m++)
            for (int k = 0; k < SB_PROBE_SH; k++)
                acc[m][k] += (ym[m] * g[k]) * weight;
        float yn[SB_PROBE_SH];
        sh9_basis(n, yn);
        vec3 lambert = rho * (first == 0u ? 0.3183098861837907 : 0.0); // rho / pi, in the first slice's pass
        for (int m = 0; m < SB_BOUNCE_SH; m++)
            for (int j = 0; j < SB_BOUNCE_SH; j++)
                op[m][j] += (ym[m] * (j == 0 ? 3.141592653589793 : 2.0943951023931953) * yn[j]) * lambert;
    }
#ifdef SUN_TABLE
    if (sun)
        sun_pass(probe, lane, r, first - sphere, hit.triangle != SB_BVH_MISS, sun_from, sun_n, sun_eps, sun_w);
#endif
    float scale = 12.566370614359172 / float(pc.ray_count);
    for (int m = 0; m < SB_BOUNCE_SH && (!sun || first == 0u); m++) { // a sun run's B: zeros, once
        for (int k = 0; k < SB_PROBE_SH; k++)
            for (int c = 0; c < 3; c++)
                partial[3 * k + c][lane] = acc[m][k][c];
        barrier();
        for (uint stride = SB_PROBE_THREADS / 2; stride > 0; stride /= 2) {
            if (lane < stride)
                for (int j = 0; j < SB_PROBE_SH * 3; j++)
                    partial[j][lane] += partial[j][lane + stride];
            barrier();
        }
        if (lane == 0)
            for (int j = 0; j < SB_PROBE_SH * 3; j++) {
                uint at = probe * pc.stride + m * SB_PROBE_SH * 3 + j;
                results[at] = (pc.accumulate != 0u ? results[at] : 0.0) + partial[j][0] * scale;
            }
        barrier();
    }
    // M comes only from the first pass (the others add nothing)
    for (int m = 0; m < SB_BOUNCE_SH && first == 0u; m++) {
        for (int j = 0; j < SB_BOUNCE_SH; j++)
            for (int c = 0; c < 3; c++)
                partial[3 * j + c][lane] = op[m][j][c];
        barrier();
        for (uint stride = SB_PROBE_THREADS / 2; stride > 0; stride /= 2) {
            if (lane < stride)
                for (int j = 0; j < SB_BOUNCE_SH * 3; j++)
                    partial[j][lane] += partial[j][lane + stride];
            barrier();
        }
        if (lane == 0)
            for (int j = 0; j < SB_BOUNCE_SH * 3; j++) {
                uint at = probe * pc.stride + SB_BOUNCE_FLOATS + m * SB_BOUNCE_SH * 3 + j;
                results[at] = (pc.accumulate != 0u ? results[at] : 0.0) + partial[j][0] * scale;
            }
        barrier();
    }
}
