#include "physics.h"

#include <math.h>
#include <string.h>

int sb_atmosphere_levels(const struct sb_atmosphere_params *p, double levels[SB_MAX_LEVELS])
{
    double thickness = p->top_radius_km - p->ground_radius_km;
    double level = 0.5 * fmin(p->rayleigh_scale_height_km, p->mie_scale_height_km);
    int n = 0;
    while (n < SB_MAX_LEVELS && level < thickness) {
        levels[n++] = level;
        level *= M_SQRT2;
    }
    return n;
}

static void put3(float dst[4], const double src[3], double w)
{
    dst[0] = (float)src[0];
    dst[1] = (float)src[1];
    dst[2] = (float)src[2];
    dst[3] = (float)w;
}

static bool any3(const double v[3])
{
    return v[0] > 0 || v[1] > 0 || v[2] > 0;
}

double sb_orders_top_km(const struct sb_atmosphere_params *p)
{
    const double air_left = 1e-6; /* of each species' column, above the grid */
    double scale_heights = log(1.0 / air_left), h = 0.0;
    if (any3(p->rayleigh_scattering_per_km))
        h = fmax(h, scale_heights * p->rayleigh_scale_height_km);
    if (any3(p->mie_scattering_per_km) || any3(p->mie_absorption_per_km))
        h = fmax(h, scale_heights * p->mie_scale_height_km);
    if (any3(p->ozone_absorption_per_km))
        h = fmax(h, p->ozone_center_km + p->ozone_half_width_km);
    return h > 0.0 ? fmin(p->top_radius_km, p->ground_radius_km + h) : p->top_radius_km;
}

double sb_orders_height_ratio(const struct sb_atmosphere_params *p, int nr)
{
    double Z = sb_orders_top_km(p) - p->ground_radius_km;
    double first = 0.25 * fmin(p->rayleigh_scale_height_km, p->mie_scale_height_km);
    int n = nr - 1;
    if (n < 1 || first * n >= Z * (1 - 1e-12))
        return 1.0;
    double lo = 1.0, hi = 1e3; /* q with (q^n - 1) / (q - 1) = Z / first, by bisection */
    for (int i = 0; i < 200; i++) {
        double q = 0.5 * (lo + hi);
        if ((pow(q, n) - 1) / (q - 1) < Z / first)
            lo = q;
        else
            hi = q;
    }
    return 0.5 * (lo + hi);
}

bool sb_orders_log_azimuth(const struct sb_atmosphere_params *p)
{
    struct sb_atmosphere_params m;
    sb_orders_medium(p, &m);
    return sb_atmosphere_peaked_dust(&m);
}

double sb_orders_azimuth_power(const struct sb_atmosphere_params *p)
{
    return sb_orders_log_azimuth(p) ? 1.0 : SB_ORDERS_NU_POWER;
}

void sb_orders_grid_pack(const struct sb_atmosphere_params *p, int nr, int nmu, int nmus, int nnu,
                         struct sb_orders_push *out)
{
    double q = sb_orders_height_ratio(p, nr), R = p->ground_radius_km, top = sb_orders_top_km(p);
    memset(out, 0, sizeof(*out));
    out->size[0] = (uint32_t)nr;
    out->size[1] = (uint32_t)nmu;
    out->size[2] = (uint32_t)nmus;
    out->size[3] = (uint32_t)nnu;
    out->heights[0] = (float)q;
    out->heights[1] = (float)log(q);
    out->heights[2] = (float)(pow(q, nr - 1) - 1.0);
    out->heights[3] = (float)(top - R);
    out->mu_s[0] = (float)(-sqrt(top * top - R * R) / top);
    out->mu_s[1] = (float)SB_ORDERS_MU_S_SPLIT;
    out->mu_s[2] = sb_orders_log_azimuth(p) ? 1.0f : 0.0f;
    out->mu_s[3] = (float)sb_orders_azimuth_power(p);
}

void sb_atmosphere_gpu_pack(const struct sb_atmosphere_params *p, struct sb_atmosphere_gpu *g)
{
    memset(g, 0, sizeof(*g));
    double mie_ext[3];
    for (int c = 0; c < 3; c++)
        mie_ext[c] = p->mie_scattering_per_km[c] + p->mie_absorption_per_km[c];
    put3(g->rayleigh_scattering, p->rayleigh_scattering_per_km, p->rayleigh_scale_height_km);
    put3(g->mie_scattering, p->mie_scattering_per_km, p->mie_scale_height_km);
    put3(g->mie_extinction, mie_ext, p->mie_g);
    put3(g->ozone_absorption, p->ozone_absorption_per_km, p->ozone_center_km);
    put3(g->ground_albedo, p->ground_albedo, p->ozone_half_width_km);
    put3(g->solar_irradiance, p->solar_irradiance, 0.0);
    double R = p->ground_radius_km, top = p->top_radius_km;
    double thickness = top - R;
    g->radii[0] = (float)R;
    g->radii[1] = (float)top;
    g->radii[2] = (float)sqrt(thickness * (top + R)); /* sqrt(top^2 - R^2) without cancellation */
    g->radii[3] = (float)thickness;
    double levels[SB_MAX_LEVELS];
    int n = sb_atmosphere_levels(p, levels);
    float *dst[4] = {g->levels_a, g->levels_b, g->levels_c, g->levels_d};
    for (int i = 0; i < SB_MAX_LEVELS; i++)
        dst[i / 4][i % 4] = i < n ? (float)levels[i] : (float)(2.0 * thickness);
    g->level_count[0] = (uint32_t)n;
}

size_t sb_lookup_float_count(enum sb_product_id id)
{
    switch (id) {
    case SB_PRODUCT_TRANSMITTANCE:
        return (size_t)SB_TRANSMITTANCE_WIDTH * SB_TRANSMITTANCE_HEIGHT * 3;
    case SB_PRODUCT_MULTISCATTERING:
        return (size_t)SB_MULTISCATTERING_LOOKUP_TEXELS * 4;
    case SB_PRODUCT_IRRADIANCE_GROUND:
        return (size_t)2 * SB_IRRADIANCE_WIDTH * 3;
    default:
        return 0;
    }
}

static float log_floor(double v)
{
    return (float)log(fmax(v, 1e-30));
}

void sb_lookup_fill(enum sb_product_id id, const struct sb_image *image, float *dst)
{
    if (id == SB_PRODUCT_TRANSMITTANCE) {
        size_t n = (size_t)image->width * image->height * 3;
        for (size_t i = 0; i < n; i++)
            dst[i] = -log_floor(image->data[i]);
    } else if (id == SB_PRODUCT_MULTISCATTERING) {
        int n = SB_MULTISCATTERING_SIZE;
        for (int j = -1; j <= n; j++)
            for (int i = -1; i <= n; i++) {
                int sj = j < 0 ? 0 : (j < n ? j : n - 1), si = i < 0 ? 0 : (i < n ? i : n - 1);
                float *texel = dst + ((size_t)(j + 1) * (n + 2) + (size_t)(i + 1)) * 4;
                for (int c = 0; c < 3; c++)
                    texel[c] = log_floor(image->data[((size_t)sj * n + si) * 3 + c]);
                texel[3] = 0.0f;
            }
    } else if (id == SB_PRODUCT_IRRADIANCE_GROUND) {
        /* Row 0 of the image is the ground, h = 0. */
        for (uint32_t x = 0; x < image->width; x++) {
            const float *texel = image->data + (size_t)x * image->channel_count;
            for (int c = 0; c < 3; c++) {
                dst[x * 3 + c] = log_floor((double)texel[c] + texel[3 + c]);
                dst[(image->width + x) * 3 + c] = log_floor(texel[3 + c]);
            }
        }
    }
}

void sb_catmull_rom(double t, double w[4])
{
    double t2 = t * t, t3 = t2 * t;
    w[0] = 0.5 * (-t3 + 2 * t2 - t);
    w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
    w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
    w[3] = 0.5 * (t3 - t2);
}

int sb_cubic_taps(double f, int n, double w[4])
{
    f = fmin(fmax(f, 0.0), n - 1.0);
    int i = n < 2 ? 0 : (int)f;
    if (i > n - 2)
        i = n - 2 < 0 ? 0 : n - 2;
    sb_catmull_rom(f - i, w);
    return i - 1;
}

size_t sb_multiscattering_refined_float_count(void)
{
    return (size_t)SB_MULTISCATTERING_REFINED_SIZE * SB_MULTISCATTERING_REFINED_SIZE * 4;
}

void sb_multiscattering_refined_fill(const struct sb_image *image, float *dst)
{
    /* from the lookup form itself, whose ghost texels repeat the edges as
     * the shaders' taps expect */
    const int n = SB_MULTISCATTERING_SIZE, stride = n + 2, m = SB_MULTISCATTERING_REFINED_SIZE;
    float lookup[SB_MULTISCATTERING_LOOKUP_TEXELS * 4];
    sb_lookup_fill(SB_PRODUCT_MULTISCATTERING, image, lookup);
    for (int y = 0; y < m; y++) {
        double wy[4];
        int y0 = sb_cubic_taps((double)y / SB_MULTISCATTERING_REFINE, n, wy);
        for (int x = 0; x < m; x++) {
            double wx[4], sum[3] = {0, 0, 0};
            int x0 = sb_cubic_taps((double)x / SB_MULTISCATTERING_REFINE, n, wx);
            for (int b = 0; b < 4; b++)
                for (int a = 0; a < 4; a++) {
                    const float *texel = lookup + ((size_t)(y0 + b + 1) * stride + x0 + a + 1) * 4;
                    for (int c = 0; c < 3; c++)
                        sum[c] += wy[b] * wx[a] * texel[c];
                }
            float *node = dst + ((size_t)y * m + x) * 4;
            for (int c = 0; c < 3; c++)
                node[c] = (float)sum[c];
            node[3] = 0.0f;
        }
    }
}

void sb_gauss_legendre_node(int k, int n, double a, double b, double *x, double *w)
{
    double z = cos(M_PI * (k + 0.75) / (n + 0.5)), dp = 1;
    for (int it = 0; it < 100; it++) {
        double p0 = 1, p1 = 0;
        for (int j = 1; j <= n; j++) {
            double p2 = p1;
            p1 = p0;
            p0 = ((2.0 * j - 1) * z * p1 - (j - 1.0) * p2) / j;
        }
        dp = n * (z * p0 - p1) / (z * z - 1);
        double dz = p0 / dp;
        z -= dz;
        if (fabs(dz) < 1e-16)
            break;
    }
    *x = 0.5 * (a + b) - 0.5 * (b - a) * z;
    *w = (b - a) / ((1 - z * z) * dp * dp);
}

double sb_reflection_level_roughness(uint32_t level, uint32_t levels)
{
    if (levels < 2 || !level)
        return 0.0;
    double t = (double)level / (levels - 1);
    return 1.0 - sqrt(fmax(1.0 - t, 0.0));
}

uint32_t sb_reflection_level_samples(uint32_t samples, uint32_t level)
{
    uint64_t s = level ? (uint64_t)samples << (level - 1) : 0;
    return s < SB_REFLECTION_MAX_SAMPLES ? (uint32_t)s : SB_REFLECTION_MAX_SAMPLES;
}

void sb_prefilter_layout(uint32_t samples, uint64_t texels, uint32_t threads, uint32_t *threads_per_texel,
                         uint32_t groups[2])
{
    uint32_t tpt = 1;
    while (tpt < threads && tpt * 16 < samples)
        tpt *= 2;
    uint64_t per_group = threads / tpt;
    uint64_t count = (texels + per_group - 1) / per_group;
    groups[0] = count < 65535 ? (uint32_t)count : 65535;
    groups[1] = (uint32_t)((count + groups[0] - 1) / groups[0]);
    *threads_per_texel = tpt;
}
