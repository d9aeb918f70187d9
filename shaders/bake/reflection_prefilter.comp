#version 450
// GGX prefiltering of a cube (config.h, sb_prefilter_push), Karis 2013's
// split-sum form with n = v = r: per texel of level `level`, the mean of
// L(l) (n.l) over a Hammersley set of half vectors drawn from GGX's
// D(h) (n.h) at alpha = roughness^2, divided by the sum of n.l, each
// sample read from the source's box-filtered mip chain at the level whose
// texels match its share of the lobe (Colbert and Krivanek 2007's filtered
// importance sampling: lod = 0.5 log2(omega_s / omega_p) + 1).
// threads_per_texel invocations a texel (about 16 samples each), each
// taking every threads_per_texel-th sample, their sums added in a fixed
// tree order (the same result whatever the scheduling). The same
// set for every texel in a frame that turns smoothly with n: no noise
// pattern changes across a face's edge, and the source is read across
// edges by direction, so the result has no seams.
#extension GL_GOOGLE_include_directive : require
#include "config.h"

layout(local_size_x = SB_PREFILTER_THREADS) in;
layout(std430, binding = SB_PREFILTER_BINDING_SOURCE) readonly buffer Source { vec4 source[]; };
layout(std430, binding = SB_PREFILTER_BINDING_OUT) writeonly buffer Out { vec4 result[]; };
layout(push_constant) uniform Push { sb_prefilter_push pc; };

#include "cube.glsl"

const float PI = 3.14159265358979;

uint source_offset(uint level)
{
    return pc.source_offsets[level / 4u][level % 4u];
}

// Bilinear within the face (texel centres; clamped at its edges) at one
// source level.
vec3 fetch(vec3 d, uint level)
{
    uint n = max(pc.face_size >> level, 1u);
    vec3 rgb;
    CUBE_BILINEAR(source, source_offset(level), n, d, rgb);
    return rgb;
}

vec3 fetch_lod(vec3 d, float lod)
{
    float top = float(pc.levels - 1u);
    lod = clamp(lod, 0.0, top);
    uint l0 = uint(lod);
    float f = lod - float(l0);
    vec3 a = fetch(d, l0);
    return f > 0.0 ? a + (fetch(d, min(l0 + 1u, pc.levels - 1u)) - a) * f : a;
}

float radical_inverse(uint i)
{
    return float(bitfieldReverse(i)) * 2.3283064365386963e-10;
}

shared vec4 partial[SB_PREFILTER_THREADS];

void main()
{
    // threads_per_texel invocations a texel (a power of two), the
    // workgroup's texels one after another in the level's row order.
    uint lane = gl_LocalInvocationID.x, tpt = pc.threads_per_texel;
    uint sub = lane % tpt;
    uint texel = (gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x) * (SB_PREFILTER_THREADS / tpt) + lane / tpt;
    uint n = max(pc.face_size >> pc.level, 1u);
    bool valid = texel < 6u * n * n; // the rest only take part in the barriers
    uvec2 t = uvec2(texel % n, min(texel / n, 6u * n - 1u));
    uint face = t.y / n;
    vec2 uv = (vec2(t.x, t.y - face * n) + 0.5) / float(n) * 2.0 - 1.0;
    vec3 N = normalize(cube_direction(face, uv));
    float a = pc.roughness * pc.roughness, a2 = a * a;
    // A frame about N that turns smoothly except at the poles (Frisvad).
    vec3 up = abs(N.y) < 0.999 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 T = normalize(cross(up, N)), B = cross(N, T);
    float omega_p = 4.0 * PI / (6.0 * float(pc.face_size) * float(pc.face_size));
    // Sums of deviations from the cube's mean (its last level): a constant
    // environment comes out exactly, and rounding is relative to the
    // lobe's contrast, not its level.
    vec3 mean = fetch(N, pc.levels - 1u);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (uint i = sub; i < pc.samples && valid; i += tpt) {
        float xi = (float(i) + 0.5) / float(pc.samples), phi = 2.0 * PI * radical_inverse(i);
        // cos^2 theta_h from q = 1 - xi, without cancellation for smooth surfaces
        float q = 1.0 - xi;
        float c2 = q / (q + a2 * xi);
        float ch = sqrt(c2), sh = sqrt(max(1.0 - c2, 0.0));
        vec3 h = T * (sh * cos(phi)) + B * (sh * sin(phi)) + N * ch;
        vec3 l = 2.0 * ch * h - N;
        float nl = dot(N, l);
        if (nl <= 0.0)
            continue;
        // pdf(l) = D(h) (n.h) / (4 v.h) = D / 4 with n = v
        float d = (c2 * (a2 - 1.0) + 1.0);
        float D = a2 / (PI * d * d);
        float omega_s = 4.0 / (float(pc.samples) * D);
        float lod = min(0.5 * log2(omega_s / omega_p) + pc.lod_bias, pc.max_lod);
        sum += (fetch_lod(l, lod) - mean) * nl;
        weight += nl;
    }
    partial[lane] = vec4(sum, weight);
    barrier();
    for (uint stride = tpt / 2u; stride > 0u; stride /= 2u) {
        if (sub < stride)
            partial[lane] += partial[lane + stride];
        barrier();
    }
    if (sub == 0u && valid) {
        vec4 total = partial[lane];
        result[pc.out_offset + t.y * n + t.x] = vec4(total.w > 0.0 ? mean + total.rgb / total.w : fetch(N, 0u), 0.0);
    }
}
