/* skyview's sky-visibility probes (probes_gpu.h, sb_probes_gpu): the grid of a
 * pack's sky_visibility product, each probe 4 vec4s (position and validity,
 * then its 9 SH coefficients of visibility), and what probe_sky.comp and
 * probe_light.comp make of them each frame: the sky's radiance as SH, and
 * each probe's irradiance as SH (rgb, in the pack's units before the
 * frame's radiance scale). The compute passes define PROBE_LIGHT_WRITABLE. */
#ifndef SB_PROBES_GLSL
#define SB_PROBES_GLSL

#include "probes_gpu.h"
#include "view_gpu.h"

#include "sh.glsl"

layout(std430, set = 0, binding = SB_VIEW_BINDING_PROBES) readonly buffer ProbeBuffer {
    sb_probes_gpu probes;
    /* per probe: (position m, valid), (sh 0-3), (sh 4-7), (sh 8, 0, 0, 0), then the
     * bounce transfer B[m][k].rgb (sky_bounce's order, 27 vec4s; zeros without),
     * then with sun_bounce its table (39 vec4s: probe_record) */
    vec4 probe_data[];
};

/* A probe's record's first vec4 (config.h): longer with the sun's table */
uint probe_record(uint i)
{
    return (probes.spacing_m.w == 2.0 ? uint(SB_PROBE_SUN_VEC4S) : uint(SB_PROBE_VEC4S)) * i;
}

#ifdef PROBE_LIGHT_WRITABLE
layout(std430, set = 0, binding = SB_VIEW_BINDING_PROBE_LIGHT) buffer ProbeLightBuffer {
#else
layout(std430, set = 0, binding = SB_VIEW_BINDING_PROBE_LIGHT) readonly buffer ProbeLightBuffer {
#endif
    vec4 sky_sh[SB_PROBE_SH];   /* rgb: the sky's (and the planet ground's) radiance */
    vec4 probe_irradiance[];    /* SB_PROBE_SH a probe, rgb: irradiance E(n) = sum_k E_k Y_k(n) */
};


/* The clamped cosine's zonal factors per band (Ramamoorthi and Hanrahan 2001). */
const float SH_COSINE[3] = float[3](SB_SH_COSINE_FACTORS);
const int SH_BAND[SB_PROBE_SH] = int[SB_PROBE_SH](SB_SH_BANDS);

#ifndef PROBE_LIGHT_WRITABLE
layout(std430, set = 0, binding = SB_VIEW_BINDING_PROBE_DETAIL) readonly buffer ProbeDetailBuffer {
    uvec4 probe_columns[]; /* the detail's table (sb_probes_gpu.detail) */
};
layout(std430, set = 0, binding = SB_VIEW_BINDING_PROBE_SIGHT) readonly buffer ProbeSightBuffer {
    uint probe_sight[]; /* SB_PROBE_SIGHT_WORDS a detail probe (config.h) */
};

/*
 * How much of the point q the detail probe whose sight mask is `mask` and
 * whose lattice point is `lattice` sees: its mask's bits (1: the segment
 * from the probe to that sample point meets nothing) interpolated
 * trilinearly at q, which lies in one of the 8 cells around the lattice
 * point; outside the samples, the nearest ones. Samples are a quarter
 * spacing apart and q stands a quarter spacing off its surface, so the 8
 * samples around q lie on its side of a flat wall: a probe behind the wall
 * sees none of them.
 */
float probe_sees(uint mask, vec3 lattice, vec3 q, float spacing)
{
    const float side = float(SB_PROBE_SIGHT_SIDE);
    vec3 t = clamp(((q - lattice) / spacing + 1.0) * (0.5 * side) - 0.5, vec3(0.0), vec3(side - 1.0));
    vec3 base = min(floor(t), vec3(side - 2.0));
    vec3 f = t - base;
    uvec3 b = uvec3(base);
    float seen = 0.0;
    for (int corner = 0; corner < 8; corner++) {
        uvec3 o = uvec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        uvec3 at = b + o;
        uint bit = (at.z * uint(SB_PROBE_SIGHT_SIDE) + at.y) * uint(SB_PROBE_SIGHT_SIDE) + at.x;
        uint word = probe_sight[mask * uint(SB_PROBE_SIGHT_WORDS) + (bit >> 5)];
        vec3 tri = mix(1.0 - f, f, vec3(o));
        seen += ((word >> (bit & 31u)) & 1u) != 0u ? tri.x * tri.y * tri.z : 0.0;
    }
    return seen;
}

/* What the probes around a point give (probe_lookup): the irradiance
 * along the normal and along the mirror direction, and the sky
 * visibility's bands 0 and 1 (sh 0, then y, z, x, as the probes store
 * them), weighted sums until normalised. */
struct probe_sample {
    vec3 e_n;
    vec3 e_r;
    vec4 sky;
};

/* Probe `index`'s irradiance along n and r (yn, yr: their SH bases), and
 * its sky visibility's bands 0 and 1 (as stored: sh 0, then y, z, x),
 * added with weight w times DDGI's wrap of the direction from pos toward
 * it and `visible` (probe_sees, at least 0.05 so that a point no probe
 * sees still gets light; 1 for a probe without a sight mask), a product
 * under 0.2 crushed toward 0 as DDGI does; an invalid probe adds nothing. */
void probe_add(uint index, float w, float visible, vec3 pos, vec3 n, float yn[SB_PROBE_SH], float yr[SB_PROBE_SH],
               inout probe_sample sum, inout float wsum)
{
    vec4 where = probe_data[probe_record(index)];
    if (w <= 0.0 || where.w == 0.0)
        return;
    vec3 to = where.xyz - pos;
    float len = length(to);
    float wrap = len > 1e-4 ? 0.5 * (dot(to / len, n) + 1.0) : 1.0;
    float seen = (wrap * wrap + 0.2) * visible;
    if (seen < 0.2) /* never with visible 1 */
        seen *= seen * seen * 25.0;
    w *= seen;
    vec3 sn = vec3(0.0), sr = vec3(0.0);
    for (int k = 0; k < SB_PROBE_SH; k++) {
        vec3 e = probe_irradiance[SB_PROBE_SH * index + k].rgb;
        sn += e * yn[k];
        sr += e * yr[k];
    }
    sum.e_n += w * max(sn, vec3(0.0));
    sum.e_r += w * max(sr, vec3(0.0));
    sum.sky += w * probe_data[probe_record(index) + 1u];
    wsum += w;
}

/* Layer l's height over the surface (a grid of layers). */
float probe_layer(int l)
{
    return probes.layers_m[l >> 2][l & 3];
}

/*
 * The detail's irradiance at pos (formats/probes.h): trilinear between the
 * 8 lattice probes around pos pushed a quarter of a step along n, weighted
 * as probe_add weighs them, invalid ones skipped and the weights
 * renormalised. Returns the detail's share: the trilinear weight of the
 * corners it has (valid or not), 1 inside it, falling to 0 over the last
 * lattice step out of it; 0 where none of its corners is valid.
 */
float probe_detail(vec3 pos, vec3 n, float yn[SB_PROBE_SH], float yr[SB_PROBE_SH], out probe_sample sum)
{
    sum = probe_sample(vec3(0.0), vec3(0.0), vec4(0.0));
    if (probes.detail.w == 0u)
        return 0.0;
    float s = probes.detail_origin_m.w;
    vec3 g = clamp((pos + n * (0.25 * s) - probes.detail_origin_m.xyz) / s, vec3(-2.0), vec3(70000.0));
    vec3 base = floor(g);
    vec3 f = g - base;
    float present = 0.0, wsum = 0.0;
    for (int corner = 0; corner < 8; corner++) {
        vec3 o = vec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        ivec3 at = ivec3(base + o);
        if (any(lessThan(at, ivec3(0))))
            continue;
        uvec3 u = uvec3(at);
        uvec2 b = u.xz / uint(SB_PROBE_BRICK);
        if (b.x >= probes.detail.x || b.y >= probes.detail.y)
            continue;
        uvec4 column = probe_columns[b.x + probes.detail.x * b.y];
        if (u.y < column.x || u.y - column.x >= column.y)
            continue;
        vec3 tri = mix(1.0 - f, f, o);
        float w = tri.x * tri.y * tri.z;
        uint brick = uint(SB_PROBE_BRICK);
        uint local = ((u.y - column.x) * brick + u.z % brick) * brick + u.x % brick;
        float visible = 1.0;
        if (probes.detail.z != 0u)
            visible = max(probe_sees(column.w + local, probes.detail_origin_m.xyz + vec3(at) * s, pos + n * (0.25 * s), s),
                          0.05);
        present += w;
        probe_add(column.z + local, w, visible, pos, n, yn, yr, sum, wsum);
    }
    if (wsum <= 1e-6) {
        sum = probe_sample(vec3(0.0), vec3(0.0), vec4(0.0));
        return 0.0;
    }
    sum = probe_sample(sum.e_n / wsum, sum.e_r / wsum, sum.sky / wsum);
    return present;
}

/*
 * The grid's irradiance at pos (the layers' or the uniform grid's) and its
 * coverage, as probe_lookup says.
 */
void probe_grid(vec3 pos, vec3 n, float yn[SB_PROBE_SH], float yr[SB_PROBE_SH], out probe_sample sum,
                out float coverage)
{
    sum = probe_sample(vec3(0.0), vec3(0.0), vec4(0.0));
    coverage = 0.0;
    if (probes.grid.x == 0u)
        return;
    vec3 spacing = probes.spacing_m.xyz;
    float wsum = 0.0;
    int layers = int(probes.layered.x);
    if (layers > 0) {
        float lowest_gap = layers > 1 ? probe_layer(1) - probe_layer(0) : probe_layer(0);
        vec3 q = pos + n * (0.25 * min(min(spacing.x, spacing.z), lowest_gap));
        vec2 g = (q.xz - probes.origin_m.xz) / spacing.xz;
        vec2 last = vec2(probes.grid.xz) - 1.0;
        vec2 outside = max(max(-g, g - last) - 0.5, vec2(0.0));
        float fade = clamp(1.0 - max(outside.x, outside.y), 0.0, 1.0);
        if (fade <= 0.0)
            return;
        vec2 c = clamp(g, vec2(0.0), last);
        vec2 base = min(floor(c), max(last - 1.0, vec2(0.0)));
        vec2 f = c - base;
        float column_cover = 0.0;
        for (int corner = 0; corner < 4; corner++) {
            vec2 o = vec2(corner & 1, corner >> 1);
            uvec2 at = uvec2(min(base + o, last));
            vec2 bi = mix(1.0 - f, f, o);
            float w = bi.x * bi.y;
            uint column = at.x + probes.grid.x * probes.grid.y * at.y; /* its layer 0 */
            float dy = q.y - probe_data[probe_record(column) + 3u].y;
            int l = 0;
            while (l + 2 < layers && dy > probe_layer(l + 1))
                l++;
            float fl = layers > 1 ? clamp((dy - probe_layer(l)) / (probe_layer(l + 1) - probe_layer(l)), 0.0, 1.0)
                                  : 0.0;
            float above = max(dy - probe_layer(layers - 1), 0.0) / spacing.y;
            float vfade = clamp(1.0 - above, 0.0, 1.0);
            column_cover += w * vfade;
            probe_add(column + probes.grid.x * uint(l), w * vfade * (1.0 - fl), 1.0, pos, n, yn, yr, sum, wsum);
            if (layers > 1)
                probe_add(column + probes.grid.x * uint(l + 1), w * vfade * fl, 1.0, pos, n, yn, yr, sum, wsum);
        }
        if (wsum <= 1e-6) {
            sum = probe_sample(vec3(0.0), vec3(0.0), vec4(0.0));
            return;
        }
        sum = probe_sample(sum.e_n / wsum, sum.e_r / wsum, sum.sky / wsum);
        coverage = fade * column_cover;
        return;
    }
    vec3 q = pos + n * (0.25 * min(spacing.x, min(spacing.y, spacing.z)));
    vec3 g = (q - probes.origin_m.xyz) / spacing;
    vec3 last = vec3(probes.grid.xyz) - 1.0;
    vec3 outside = max(max(-g, g - last) - 0.5, vec3(0.0)); /* each probe owns a cell around it */
    float fade = clamp(1.0 - max(outside.x, max(outside.y, outside.z)), 0.0, 1.0);
    if (fade <= 0.0)
        return;
    vec3 c = clamp(g, vec3(0.0), last);
    vec3 base = min(floor(c), max(last - 1.0, vec3(0.0)));
    vec3 f = c - base;
    for (int corner = 0; corner < 8; corner++) {
        vec3 o = vec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        uvec3 at = uvec3(min(base + o, last));
        vec3 tri = mix(1.0 - f, f, o);
        uint index = at.x + probes.grid.x * (at.y + probes.grid.y * at.z);
        probe_add(index, tri.x * tri.y * tri.z, 1.0, pos, n, yn, yr, sum, wsum);
    }
    if (wsum <= 1e-6) {
        sum = probe_sample(vec3(0.0), vec3(0.0), vec4(0.0));
        return;
    }
    sum = probe_sample(sum.e_n / wsum, sum.e_r / wsum, sum.sky / wsum);
    coverage = fade;
}

/*
 * Irradiance from the probes at world point pos (m) on a surface of normal
 * n, and along a second direction r (the mirror direction, for the
 * ambient specular): the detail's where it is, the grid's elsewhere, the
 * two blended by the detail's share over its last lattice step, so no
 * seam shows where the detail ends. *coverage is 1 where either covers
 * pos, fading to 0 where neither does (the caller lights the rest by the
 * sky alone).
 *
 * The grid: trilinear between the 8 grid probes around pos pushed a
 * quarter of a spacing along n, each weighted by DDGI's wrap of the
 * direction toward it, probes flagged invalid skipped and the weights
 * renormalised; its coverage is 1 inside the grid (and half a spacing
 * past its outer probes), fading to 0 one spacing further, and 0 with no
 * probe (or no valid one) around.
 *
 * A grid of layers over the surface: bilinear between the 4 columns
 * around pos, and in each column linear between the two layers around
 * pos's height over that column's surface (below the lowest, the lowest;
 * above the top, the top, fading to nothing over the y spacing).
 */
void probe_lookup(vec3 pos, vec3 n, vec3 r, out probe_sample light, out float coverage)
{
    light = probe_sample(vec3(0.0), vec3(0.0), vec4(0.0));
    coverage = 0.0;
    if (probes.grid.w == 0u)
        return;
    float yn[SB_PROBE_SH], yr[SB_PROBE_SH];
    sh9_basis(n, yn);
    sh9_basis(r, yr);
    probe_sample detail_light;
    float detail = probe_detail(pos, n, yn, yr, detail_light);
    if (detail >= 1.0 - 1e-6) {
        light = detail_light;
        coverage = 1.0;
        return;
    }
    probe_sample grid_light;
    float grid;
    probe_grid(pos, n, yn, yr, grid_light, grid);
    if (detail <= 0.0) { /* the grid's alone, as it was */
        light = grid_light;
        coverage = grid;
        return;
    }
    coverage = detail + (1.0 - detail) * grid;
    if (coverage <= 1e-6)
        return;
    float a = detail / coverage, b = (1.0 - detail) * grid / coverage;
    light = probe_sample(a * detail_light.e_n + b * grid_light.e_n, a * detail_light.e_r + b * grid_light.e_r,
                         a * detail_light.sky + b * grid_light.sky);
}

/*
 * Specular occlusion (Oat and Sander 2007's ambient aperture): the share
 * of a GGX lobe around the mirror direction r that reaches the sky, from
 * the probes' visibility (probe_sample.sky: sh 0, then y, z, x). The
 * visible sky as a cone: its solid angle from band 0 (Omega = 2 sqrt(pi)
 * v0), its axis along band 1; the lobe as the cone that holds half of
 * GGX's energy at normal incidence (the half vector's median angle
 * atan(alpha), doubled by the reflection). The share is the two cones'
 * intersection over the lobe's, the intersection their smaller cone's
 * solid angle faded by a smoothstep over the axes' angle from where one
 * holds the other to where they part. 1 - cos x is written 2 sin^2(x/2),
 * exact for the small lobes of smooth surfaces.
 */
float probe_specular_occlusion(vec4 sky, vec3 r, float roughness)
{
    float omega = 3.5449077018110318 * clamp(sky.x, 0.0, 3.5449077018110318); /* 2 sqrt(pi) v0, to 4 pi */
    float aperture = 2.0 * asin(sqrt(clamp(omega / 12.566370614359172, 0.0, 1.0))); /* 2 pi (1 - cos a) = omega */
    float a = roughness * roughness;
    float lobe = min(2.0 * atan(a), 1.5707963267948966);
    vec3 axis = sky.wyz; /* x, y, z */
    float len = length(axis);
    float apart = len > 1e-6 ? acos(clamp(dot(axis / len, r), -1.0, 1.0)) : 0.0;
    float inner = abs(aperture - lobe), outer = aperture + lobe;
    float overlap = 1.0 - smoothstep(0.0, 1.0, (apart - inner) / max(outer - inner, 1e-6));
    float smaller = sin(0.5 * min(aperture, lobe)), whole = sin(0.5 * lobe);
    return clamp(smaller * smaller / max(whole * whole, 1e-12) * overlap, 0.0, 1.0);
}
#endif

#endif
