/*
 * The CPU reference of the cloud noise (definitions in clouds.h), in fp32
 * with the same operations in the same order as shaders/noise.glsl, so that
 * the two agree bit for bit. ISO C mode (-std=c11) keeps GCC from fusing
 * multiplies and adds (-ffp-contract=off), and x86-64 evaluates float in
 * float (FLT_EVAL_METHOD 0).
 */
#include <math.h>
#include <string.h>

#include "clouds.h"

#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0
#error "the cloud noise reference needs float evaluated in float"
#endif

/* 1 / (1 + 1/2 + ... + 2^(1-n)) rounded to fp32, as in noise.glsl. */
static const float fbm_norm[SB_NOISE_MAX_OCTAVES + 1] = {
    0.0f,         1.0f,         0.666666686534881591796875f, 0.571428596973419189453125f, 0.533333361148834228515625f,
    0.516129016876220703125f, 0.507936537265777587890625f, 0.5039370059967041015625f, 0.501960813999176025390625f,
};

static void hash3(uint32_t v[3])
{
    for (int i = 0; i < 3; i++)
        v[i] = v[i] * 1664525u + 1013904223u;
    v[0] += v[1] * v[2];
    v[1] += v[2] * v[0];
    v[2] += v[0] * v[1];
    for (int i = 0; i < 3; i++)
        v[i] ^= v[i] >> 16;
    v[0] += v[1] * v[2];
    v[1] += v[2] * v[0];
    v[2] += v[0] * v[1];
}

static void lattice(const int c[3], int period, uint32_t seed, uint32_t out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = (uint32_t)(c[i] >= period ? c[i] - period : c[i] < 0 ? c[i] + period : c[i]);
    out[2] += seed * 0x9E3779B9u;
    hash3(out);
}

static float unit(uint32_t h)
{
    return (float)(h >> 8) * (1.0f / 16777216.0f);
}

static float bits_float(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof(f));
    return f;
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof(u));
    return u;
}

static float noise_sqrt(float x)
{
    if (x <= 0.0f)
        return 0.0f;
    float y = bits_float(0x5F375A86u - (float_bits(x) >> 1));
    for (int i = 0; i < 4; i++) {
        float xyy = x * y * y;
        y = y * (1.5f - 0.5f * xyy);
    }
    return x * y;
}

static float clamp01(float v)
{
    return fminf(fmaxf(v, 0.0f), 1.0f);
}

static float perlin(const float p[3], int period, uint32_t seed)
{
    float f[3], u[3];
    int c[3];
    for (int i = 0; i < 3; i++) {
        float x = p[i] * (float)period;
        float cf = floorf(x);
        c[i] = (int)cf;
        f[i] = x - cf;
        u[i] = f[i] * f[i] * f[i] * (f[i] * (f[i] * 6.0f - 15.0f) + 10.0f);
    }
    float corner[8];
    for (int k = 0; k < 8; k++) {
        int o[3] = {k & 1, (k >> 1) & 1, (k >> 2) & 1}, at[3] = {c[0] + o[0], c[1] + o[1], c[2] + o[2]};
        uint32_t h[3];
        lattice(at, period, seed, h);
        uint32_t g = ((h[0] >> 8) * 12u) >> 24, axis = g >> 2;
        float d[3] = {f[0] - (float)o[0], f[1] - (float)o[1], f[2] - (float)o[2]};
        float s0 = (g & 1u) ? -1.0f : 1.0f, s1 = (g & 2u) ? -1.0f : 1.0f;
        corner[k] = axis == 0 ? s0 * d[0] + s1 * d[1] : axis == 1 ? s0 * d[0] + s1 * d[2] : s0 * d[1] + s1 * d[2];
    }
    float x00 = corner[0] + u[0] * (corner[1] - corner[0]);
    float x10 = corner[2] + u[0] * (corner[3] - corner[2]);
    float x01 = corner[4] + u[0] * (corner[5] - corner[4]);
    float x11 = corner[6] + u[0] * (corner[7] - corner[6]);
    float y0 = x00 + u[1] * (x10 - x00);
    float y1 = x01 + u[1] * (x11 - x01);
    return y0 + u[2] * (y1 - y0);
}

static float perlin_fbm(const float p[3], int period, int octaves, uint32_t seed)
{
    float sum = 0.0f, weight = 1.0f;
    for (int k = 0; k < octaves; k++) {
        sum += weight * perlin(p, period << k, seed + (uint32_t)k);
        weight *= 0.5f;
    }
    return clamp01(0.5f + 0.5f * sum * fbm_norm[octaves]);
}

static float worley(const float p[3], int cells, uint32_t seed)
{
    float f[3];
    int c[3];
    for (int i = 0; i < 3; i++) {
        float x = p[i] * (float)cells, cf = floorf(x);
        c[i] = (int)cf;
        f[i] = x - cf;
    }
    float best = 8.0f;
    for (int k = 0; k < 27; k++) { /* x fastest, as noise.glsl's loops */
        int o[3] = {k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1}, at[3] = {c[0] + o[0], c[1] + o[1], c[2] + o[2]};
        uint32_t h[3];
        lattice(at, cells, seed, h);
        float d[3];
        for (int i = 0; i < 3; i++)
            d[i] = f[i] - (float)o[i] - unit(h[i]);
        float d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        best = fminf(best, d2);
    }
    return 1.0f - noise_sqrt(fminf(best, 1.0f));
}

static float worley_fbm(const float p[3], int cells, uint32_t seed)
{
    return worley(p, cells, seed) * 0.625f + worley(p, cells * 2, seed + 1u) * 0.25f +
           worley(p, cells * 4, seed + 2u) * 0.125f;
}

static float curl(const float p[3], int period, int octaves, uint32_t seed, uint32_t axis)
{
    const float h = 1.0f / 4096.0f;
    uint32_t i0 = (axis + 2u) % 3u, j0 = (axis + 1u) % 3u, i1 = (axis + 1u) % 3u, j1 = (axis + 2u) % 3u;
    float a[3], b[3];
    for (int i = 0; i < 3; i++) {
        a[i] = p[i] + ((uint32_t)i == j0 ? h : 0.0f);
        b[i] = p[i] - ((uint32_t)i == j0 ? h : 0.0f);
    }
    float d0 = perlin_fbm(a, period, octaves, seed + 16u * i0) - perlin_fbm(b, period, octaves, seed + 16u * i0);
    for (int i = 0; i < 3; i++) {
        a[i] = p[i] + ((uint32_t)i == j1 ? h : 0.0f);
        b[i] = p[i] - ((uint32_t)i == j1 ? h : 0.0f);
    }
    float d1 = perlin_fbm(a, period, octaves, seed + 16u * i1) - perlin_fbm(b, period, octaves, seed + 16u * i1);
    return clamp01(0.5f + (d0 - d1) * (2048.0f / 16.0f));
}

void sb_cloud_ref(const struct sb_noise_push *pc, uint64_t first, uint64_t count, float *out)
{
    for (uint64_t t = 0; t < count; t++) {
        uint64_t index = first + t;
        uint32_t id[3] = {(uint32_t)(index % pc->size_x), (uint32_t)(index / pc->size_x % pc->size_y),
                          (uint32_t)(index / ((uint64_t)pc->size_x * pc->size_y))};
        float p[3] = {((float)id[0] + 0.5f) * pc->inv_x, ((float)id[1] + 0.5f) * pc->inv_y,
                      ((float)id[2] + 0.5f) * pc->inv_z};
        if (pc->size_z == 1)
            p[2] = pc->slice_z;
        for (uint32_t ch = 0; ch < pc->channel_count; ch++) {
            uint32_t kind = pc->kind[ch], seed = pc->seed[ch];
            int a = (int)pc->a[ch], b = (int)pc->b[ch], c = (int)pc->c[ch];
            float v;
            if (kind == SB_NOISE_PERLIN_WORLEY) {
                float w = worley_fbm(p, c, seed + 100u);
                v = w + perlin_fbm(p, a, b, seed) * (1.0f - w);
            } else if (kind == SB_NOISE_WORLEY_FBM) {
                v = worley_fbm(p, a, seed);
            } else if (kind == SB_NOISE_PERLIN_FBM) {
                v = clamp01(0.5f + (perlin_fbm(p, a, b, seed) - 0.5f) * (float)(1u << c));
            } else {
                v = curl(p, a, b, seed, (uint32_t)c);
            }
            out[t * pc->channel_count + ch] = v;
        }
    }
}
