// GGX prefiltering of a cube, Karis 2013's split-sum form with n = v = r,
// shared by the bake (bake/reflection_prefilter.comp) and skyview's
// relight (view/reflection_filter.comp): per texel of a level, the mean of
// L(l) (n.l) over a Hammersley set of half vectors drawn from GGX's
// D(h) (n.h) at alpha = roughness^2, divided by the sum of n.l, each
// sample read from the source's box-filtered mip chain at the level whose
// texels match its share of the lobe (Colbert and Krivanek 2007's filtered
// importance sampling: lod = 0.5 log2(omega_s / omega_p), plus lod_bias).
// threads_per_texel invocations a texel, each taking every
// threads_per_texel-th sample, their sums added in a fixed tree order (the
// same result whatever the scheduling). The same set for every texel in a
// frame that turns smoothly with n: no noise pattern changes across a
// face's edge, and the source is read across edges by direction, so the
// result has no seams.
//
// The includer defines PREFILTER_THREADS (its workgroup's size) and
// `vec3 prefilter_fetch(vec3 d, uint level)` (bilinear within the face at
// a source level) before including this.
#ifndef SB_PREFILTER_GLSL
#define SB_PREFILTER_GLSL

#include "cube.glsl"

struct prefilter_level {
    uint face_size;         // level 0's
    uint levels;            // the source chain's
    uint level;             // written
    uint samples;           // a texel's
    float roughness;        // perceptual
    float lod_bias;
    float max_lod;          // no coarser source level than this
    uint threads_per_texel; // a power of two up to PREFILTER_THREADS
    uint groups_x;          // workgroups along x; a workgroup's index is y groups_x + x
};

vec3 prefilter_fetch_lod(vec3 d, float lod, uint levels)
{
    float top = float(levels - 1u);
    lod = clamp(lod, 0.0, top);
    uint l0 = uint(lod);
    float f = lod - float(l0);
    vec3 a = prefilter_fetch(d, l0);
    return f > 0.0 ? a + (prefilter_fetch(d, min(l0 + 1u, levels - 1u)) - a) * f : a;
}

float prefilter_radical_inverse(uint i)
{
    return float(bitfieldReverse(i)) * 2.3283064365386963e-10;
}

shared vec4 prefilter_partial[PREFILTER_THREADS];

// This invocation's texel of the level, and whether it has one (the rest
// only take part in the barriers); then the texel's filtered radiance in
// *result, valid in the texel's first invocation (returns true there).
bool prefilter_run(prefilter_level p, out uint texel, out vec3 result)
{
    const float PI_ = 3.14159265358979;
    uint lane = gl_LocalInvocationID.x, tpt = p.threads_per_texel;
    uint sub = lane % tpt;
    texel = (gl_WorkGroupID.y * p.groups_x + gl_WorkGroupID.x) * (PREFILTER_THREADS / tpt) + lane / tpt;
    uint n = max(p.face_size >> p.level, 1u);
    bool valid = texel < 6u * n * n;
    uvec2 t = uvec2(texel % n, min(texel / n, 6u * n - 1u));
    uint face = t.y / n;
    vec2 uv = (vec2(t.x, t.y - face * n) + 0.5) / float(n) * 2.0 - 1.0;
    vec3 N = normalize(cube_direction(face, uv));
    float a = p.roughness * p.roughness, a2 = a * a;
    // A frame about N that turns smoothly except at the poles (Frisvad).
    vec3 up = abs(N.y) < 0.999 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 T = normalize(cross(up, N)), B = cross(N, T);
    float omega_p = 4.0 * PI_ / (6.0 * float(p.face_size) * float(p.face_size));
    // Sums of deviations from the cube's mean (its last level): a constant
    // environment comes out exactly, and rounding is relative to the
    // lobe's contrast, not its level.
    vec3 mean = prefilter_fetch(N, p.levels - 1u);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (uint i = sub; i < p.samples && valid; i += tpt) {
        float xi = (float(i) + 0.5) / float(p.samples), phi = 2.0 * PI_ * prefilter_radical_inverse(i);
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
        float D = a2 / (PI_ * d * d);
        float omega_s = 4.0 / (float(p.samples) * D);
        float lod = min(0.5 * log2(omega_s / omega_p) + p.lod_bias, p.max_lod);
        sum += (prefilter_fetch_lod(l, lod, p.levels) - mean) * nl;
        weight += nl;
    }
    prefilter_partial[lane] = vec4(sum, weight);
    barrier();
    for (uint stride = tpt / 2u; stride > 0u; stride /= 2u) {
        if (sub < stride)
            prefilter_partial[lane] += prefilter_partial[lane + stride];
        barrier();
    }
    vec4 total = prefilter_partial[lane];
    result = total.w > 0.0 ? mean + total.rgb / total.w : prefilter_fetch(N, 0u);
    texel = t.y * n + t.x;
    return sub == 0u && valid;
}

#endif
