/*
 * The atmosphere products baked on the Vulkan device (validation on) against
 * the independent fp64 CPU reference in baker/atmosphere_ref.c.
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "accuracy.h"
#include "atmosphere.h"
#include "atmosphere_probe.h"
#include "atmosphere_probe.spv.h"
#include "atmosphere_ref.h"
#include "context.h"
#include "harness_vk.h"
#include "log.h"
#include "parallel.h"
#include "spectral.h"
#include "spectrum.h"

static struct sb_atmosphere_params earth;
static struct sb_image luts[SB_PRODUCT_COUNT];

/* ---- transmittance: every texel ------------------------------------------------ */

struct t_job {
    double max_rel[3];
    int worst[2];
    double rows_max[SB_TRANSMITTANCE_HEIGHT];
    int rows_worst[SB_TRANSMITTANCE_HEIGHT];
    double rms_acc[SB_TRANSMITTANCE_HEIGHT];
    int rms_n[SB_TRANSMITTANCE_HEIGHT];
};

static void transmittance_row(void *user, int y)
{
    struct t_job *job = user;
    const struct sb_image *lut = &luts[SB_PRODUCT_TRANSMITTANCE];
    job->rows_max[y] = 0;
    for (uint32_t x = 0; x < lut->width; x++) {
        double r, mu, ref[3];
        sb_ref_transmittance_geometry(&earth, (double)x / (lut->width - 1), (double)y / (lut->height - 1), &r, &mu);
        sb_ref_transmittance(&earth, r, mu, 8, ref);
        for (int c = 0; c < 3; c++) {
            double gpu = lut->data[((uint32_t)y * lut->width + x) * 3 + c];
            if (ref[c] <= 1e-6)
                continue;
            double rel = fabs(gpu / ref[c] - 1.0);
            job->rms_acc[y] += rel * rel;
            job->rms_n[y]++;
            if (rel > job->rows_max[y]) {
                job->rows_max[y] = rel;
                job->rows_worst[y] = (int)x;
            }
        }
    }
}

static void test_transmittance(void)
{
    struct t_job job = {0};
    sb_parallel_for(SB_TRANSMITTANCE_HEIGHT, transmittance_row, &job);
    double max_rel = 0, acc = 0;
    int n = 0, wx = 0, wy = 0;
    for (int y = 0; y < SB_TRANSMITTANCE_HEIGHT; y++) {
        acc += job.rms_acc[y];
        n += job.rms_n[y];
        if (job.rows_max[y] > max_rel) {
            max_rel = job.rows_max[y];
            wx = job.rows_worst[y];
            wy = y;
        }
    }
    printf("transmittance: max rel error %.3g at texel (%d, %d), rms %.3g over %d values with T > 1e-6\n", max_rel, wx,
           wy, sqrt(acc / n), n);
    /* The bound: 1e-5 relative against fp64 for every T > 1e-6. */
    CHECK(max_rel <= 1e-5, "max relative error %.3g", max_rel);
}

/* ---- the GLSL model's functions, one by one ------------------------------------ */

#define PROBE_RECORDS 1024

/*
 * Points where the functions of atmosphere.glsl are evaluated on the device:
 * (h, mu) pairs from the ground to the top, zenith to the horizon and
 * grazing rays just above it; LUT coordinates on a grid that includes the
 * edges 0 and 1; every texel of the sub-texel LUTs.
 */
static int probe_directions(double (*dirs)[2], int max)
{
    static const double hs[] = {0, 1e-3, 0.1, 1, 3, 9.99, 10, 25, 40, 60, 80, 99.99, 100};
    static const double mus[] = {1, 0.9, 0.5, 0.2, 0.1, 0.03, 0.01, 1e-3, 0, -1e-3, -0.01, -0.03, -0.1, -0.15};
    static const double above_horizon[] = {1e-2, 1e-3, 2e-4};
    double R = earth.ground_radius_km;
    int n = 0;
    for (size_t i = 0; i < sizeof(hs) / sizeof(hs[0]); i++) {
        double r = R + hs[i], mu_h = -sqrt(fmax(1 - (R / r) * (R / r), 0.0));
        for (size_t j = 0; j < sizeof(mus) / sizeof(mus[0]) && n < max; j++)
            if (mus[j] > mu_h + 2e-4) {
                dirs[n][0] = hs[i];
                dirs[n++][1] = mus[j];
            }
        for (size_t j = 0; j < 3 && hs[i] > 0 && n < max; j++) {
            dirs[n][0] = hs[i];
            dirs[n++][1] = mu_h + above_horizon[j];
        }
    }
    return n;
}

/* The k-th point of a multiscattering lookup: the LUT's edges (h = 0 and
 * the top, mu_s = -1 and 1) one time in four each, else anywhere. */
static void lookup_point(int k, float *h, float *mu_s)
{
    double v[2];
    for (int i = 0; i < 2; i++)
        v[i] = fmod((k + 1) * (i ? 0.7548776662466927 : 0.5698402909980532), 1.0);
    double thickness = earth.top_radius_km - earth.ground_radius_km;
    *h = (float)(k % 4 == 0 ? (k % 8 ? thickness : 0.0) : thickness * v[0]);
    *mu_s = (float)(k % 4 == 1 ? (k % 8 == 1 ? -1.0 : 1.0) : -1 + 2 * v[1]);
}

static void test_probe(struct sb_atmosphere_baker *baker)
{
    static const double grid[] = {0, 0.5 / 256, 0.5 / 64, 0.1, 0.25, 0.5, 0.75, 0.9, 1 - 0.5 / 64, 1 - 0.5 / 256, 1};
    enum { NG = sizeof(grid) / sizeof(grid[0]) };
    double dirs[256][2];
    int ndirs = probe_directions(dirs, 256);
    float *rec = calloc((size_t)PROBE_RECORDS * PROBE_FLOATS, sizeof(float));
    for (int k = 0; k < PROBE_RECORDS; k++) {
        float *in = rec + k * PROBE_FLOATS;
        in[0] = (float)dirs[k % ndirs][0];
        in[1] = (float)dirs[k % ndirs][1];
        in[2] = (float)grid[k % NG];
        in[3] = (float)grid[(k / NG) % NG];
        in[4] = (float)(k % SB_MULTISCATTERING_SIZE);
        in[5] = (float)(k / SB_MULTISCATTERING_SIZE);
        in[6] = (float)(k % SB_IRRADIANCE_WIDTH);
        in[7] = (float)(k / SB_IRRADIANCE_WIDTH);
        sun_table_ray(&earth, k, &in[PROBE_SUN], &in[PROBE_SUN + 1]);
        lookup_point(k, &in[20], &in[21]);
    }
    float *inputs = malloc((size_t)PROBE_RECORDS * PROBE_FLOATS * sizeof(float));
    memcpy(inputs, rec, (size_t)PROBE_RECORDS * PROBE_FLOATS * sizeof(float));
    enum sb_result res = sb_atmosphere_run_kernel(baker, sb_spv_atmosphere_probe, sizeof(sb_spv_atmosphere_probe), rec,
                                                  PROBE_RECORDS, PROBE_FLOATS);
    CHECK(res == SB_OK, "probe kernel: %s", sb_result_name(res));

    double exact_worst = -1, lut_worst = 0, coords_worst = 0, trip_worst = 0, geo_h = 0, geo_mu = 0, sub_worst = 0;
    double psi_worst = -1, mimic_worst = -1;
    int exact_at = 0, lut_at = 0, psi_at = 0, mimic_at = 0;
    struct sun_table_worst sun = {0};
    for (int k = 0; !res && k < PROBE_RECORDS; k++) {
        const float *in = inputs + k * PROBE_FLOATS, *out = rec + k * PROBE_FLOATS;
        double h = in[0], mu = in[1], r = earth.ground_radius_km + h, ref[3];
        if (k < ndirs) {
            /* The input itself is fp32: near the horizon one ulp of mu moves the
             * tangent point by millimetres, which changes a large optical depth
             * by more than 1e-5, and the shader rounds r mu and (r mu)^2 on
             * its way to the tangent point. The bound is 1e-5 plus the change
             * that 4 ulp of mu make. */
            double ref_next[3], ulp = nextafterf((float)mu, 2.0f) - (float)mu, mimic[3], mimic_next[3];
            sb_ref_transmittance(&earth, r, mu, 8, ref);
            sb_ref_transmittance(&earth, r, mu + 4 * ulp, 8, ref_next);
            /* the lookup against the same lookup in fp64 from the same LUT:
             * 1e-5 for the fp32 sums and exponential, plus what 4 ulp of mu
             * change */
            sb_ref_transmittance_lookup(&earth, &luts[SB_PRODUCT_TRANSMITTANCE], r, mu, mimic);
            sb_ref_transmittance_lookup(&earth, &luts[SB_PRODUCT_TRANSMITTANCE], r, mu + 4 * ulp, mimic_next);
            for (int c = 0; c < 3; c++) {
                if (ref[c] <= 1e-6)
                    continue;
                double lookup_excess = rel_err(out[3 + c], mimic[c]) - 1e-5 - rel_err(mimic_next[c], mimic[c]);
                if (lookup_excess > mimic_worst) {
                    mimic_worst = lookup_excess;
                    mimic_at = k;
                }
                double excess = rel_err(out[c], ref[c]) - 1e-5 - rel_err(ref_next[c], ref[c]);
                if (excess > exact_worst) {
                    exact_worst = excess;
                    exact_at = k;
                }
                if (rel_err(out[3 + c], ref[c]) > lut_worst) {
                    lut_worst = rel_err(out[3 + c], ref[c]);
                    lut_at = k;
                }
            }
            double xm, xr;
            sb_ref_transmittance_coords(&earth, r, mu, &xm, &xr);
            coords_worst = fmax(coords_worst, fmax(fabs(out[6] - xm), fabs(out[7] - xr)));
        }
        /* The sun table against fp64: its interpolation is good to ~1e-5
         * in optical depth on the earth (docs/accuracy.md), the bound 2e-5. */
        sun_table_record(&earth, in[PROBE_SUN], in[PROBE_SUN + 1], out + PROBE_SUN, 2e-5, &sun);
        /* The multiscattering lookup against the same lookup in fp64 from
         * the same LUT: the sums of fp32 logarithms (|ln psi| < 70, down to
         * the floor) leave 1e-5; the coordinates' roundings, a few ulp of
         * 31 texels, count where ln psi is steep (at night it falls to the
         * floor within a texel), so the bound adds what 4 ulp of either
         * input change. */
        const struct sb_image *ms_lut = &luts[SB_PRODUCT_MULTISCATTERING];
        double psi[3], psi_h[3], psi_mu[3];
        float ph = in[20], pmu = in[21];
        sb_ref_multiscattering_lookup(&earth, ms_lut, ph, pmu, psi);
        sb_ref_multiscattering_lookup(&earth, ms_lut, ph + 4 * (nextafterf(ph, 1e9f) - ph), pmu, psi_h);
        sb_ref_multiscattering_lookup(&earth, ms_lut, ph, pmu - 4 * (pmu - nextafterf(pmu, -2.0f)), psi_mu);
        for (int c = 0; c < 3; c++) {
            double excess =
                rel_err(out[20 + c], psi[c]) - 1e-5 - rel_err(psi_h[c], psi[c]) - rel_err(psi_mu[c], psi[c]);
            if (psi[c] > 1e-20 && excess > psi_worst) {
                psi_worst = excess;
                psi_at = k;
            }
        }
        double rr, rmu;
        sb_ref_transmittance_geometry(&earth, in[2], in[3], &rr, &rmu);
        geo_h = fmax(geo_h, fabs(out[8] - (rr - earth.ground_radius_km)));
        geo_mu = fmax(geo_mu, fabs(out[9] - rmu));
        /* in e / (d_max - d_min) = (1 - x_mu)^2, linear in the ray (below) */
        double e_in = (1.0 - in[2]) * (1.0 - in[2]), e_back = (1.0 - out[10]) * (1.0 - out[10]);
        trip_worst = fmax(trip_worst, fmax(fabs(e_back - e_in), fabs(out[11] - in[3])));
        if (k < SB_MULTISCATTERING_SIZE * SB_MULTISCATTERING_SIZE)
            sub_worst = fmax(sub_worst, fmax(fabs(out[12] - in[4]), fabs(out[13] - in[5])));
        if (k < SB_IRRADIANCE_WIDTH * SB_IRRADIANCE_HEIGHT)
            sub_worst = fmax(sub_worst, fmax(fabs(out[14] - in[6]), fabs(out[15] - in[7])));
    }
    printf("transmittance_to_top: worst error minus (1e-5 + 4-ulp sensitivity) %.3g over %d rays (h %.4g mu %.6g)\n",
           exact_worst, ndirs, inputs[exact_at * PROBE_FLOATS], inputs[exact_at * PROBE_FLOATS + 1]);
    /* The LUT read as the runtime reads it (bilinear in the optical depth):
     * against the exact transmittance within the 1e-2 between texels
     * (the bakes integrate the sun's transmittance instead), and against the
     * same read in fp64 (sb_ref_transmittance_lookup, which the bench's
     * transmittance_resolution measures) within its rounding. */
    printf("transmittance LUT lookup: max rel error %.3g (worst h %.4g mu %.6g); against its fp64 mimic, worst minus "
           "(1e-5 + 4-ulp sensitivity) %.3g (h %.4g mu %.6g)\n",
           lut_worst, inputs[lut_at * PROBE_FLOATS], inputs[lut_at * PROBE_FLOATS + 1], mimic_worst,
           inputs[mimic_at * PROBE_FLOATS], inputs[mimic_at * PROBE_FLOATS + 1]);
    CHECK(lut_worst <= 1e-2, "transmittance LUT lookup: %.3g from the exact transmittance", lut_worst);
    CHECK(mimic_worst <= 0, "transmittance LUT lookup: %.3g beyond its bound against fp64", mimic_worst);
    printf(
        "transmittance mapping: coords %.3g, geometry h %.3g km mu %.3g, round trip %.3g; sub-texel round trip %.3g\n",
        coords_worst, geo_h, geo_mu, trip_worst, sub_worst);
    CHECK(exact_worst <= 0, "transmittance_to_top: %.3g beyond its bound", exact_worst);
    printf("sun table: worst error minus (2e-5 + 4-ulp sensitivity) %.3g over %d values (h %.4g mu %.6g: %.3g in "
           "optical depth)\n",
           sun.excess, sun.count, sun.h, sun.mu, sun.tau);
    CHECK(sun.count > PROBE_RECORDS && sun.excess <= 0, "sun table: %.3g beyond its bound", sun.excess);
    printf("multiscattering lookup: worst error minus (1e-5 + 4-ulp sensitivity) %.3g over %d points (h %.4g mu_s "
           "%.6g)\n",
           psi_worst, PROBE_RECORDS, inputs[psi_at * PROBE_FLOATS + 20], inputs[psi_at * PROBE_FLOATS + 21]);
    CHECK(psi_worst <= 0, "multiscattering lookup: %.3g beyond its bound", psi_worst);
    /*
     * Mappings. fp32 budget: coordinates come from distances of up to 2300 km
     * (ulp 2.4e-4 km) over spans of >= 1034 km, a few roundings each: 2e-6
     * of the unit range; the round trip goes through mu and back, whose
     * conditioning near the zenith (d barely depends on mu) costs another
     * factor of a few: 1e-5, a 250th of a texel. It is measured in e / (d_max
     * - d_min) = (1 - x_mu)^2, which is linear in the ray: x_mu, its square
     * root, is infinitely steep at the horizon, where one ulp of mu moves it
     * by 2e-4 (while the optical depth, quadratic in 1 - x_mu there, barely
     * moves). Geometry against fp64:
     * h = rho^2 / (r + R) carries twice rho's rounding plus its own, a few
     * ulp of 100 km (7.6e-6 km each): 4e-5 km; mu to 2e-5. Sub-texel mappings
     * are linear: 4 ulp of 63.
     */
    CHECK(coords_worst <= 2e-6, "transmittance coords: %.3g", coords_worst);
    CHECK(trip_worst <= 1e-5, "transmittance round trip: %.3g", trip_worst);
    CHECK(geo_h <= 4e-5 && geo_mu <= 2e-5, "transmittance geometry: h %.3g mu %.3g", geo_h, geo_mu);
    CHECK(sub_worst <= 4 * 63 * FLT_EPSILON, "sub-texel round trip: %.3g", sub_worst);
    free(rec);
    free(inputs);
}

/* ---- products with sampled texels --------------------------------------------- */

struct sample_job {
    enum sb_product_id id;
    int xs[16], ys[16], nx, ny;
    double ref[256][9];
};

static double texel_unit(int i, int n)
{
    return (double)i / (n - 1);
}

static void sample_texel(void *user, int k)
{
    struct sample_job *job = user;
    const struct sb_image *lut = &luts[job->id];
    int x = job->xs[k % job->nx], y = job->ys[k / job->nx];
    double mu_s = 2.0 * texel_unit(x, (int)lut->width) - 1.0;
    double h = (earth.top_radius_km - earth.ground_radius_km) * texel_unit(y, (int)lut->height);
    switch (job->id) {
    case SB_PRODUCT_MULTISCATTERING:
        sb_ref_multiscattering(&earth, h, mu_s, NULL, job->ref[k]);
        break;
    case SB_PRODUCT_IRRADIANCE_GROUND:
        sb_ref_irradiance_ground(&earth, h, mu_s, &luts[SB_PRODUCT_MULTISCATTERING], NULL, job->ref[k],
                                 job->ref[k] + 3);
        break;
    default:
        sb_ref_irradiance_sky(&earth, h, mu_s, &luts[SB_PRODUCT_MULTISCATTERING], &luts[SB_PRODUCT_IRRADIANCE_GROUND],
                              NULL, job->ref[k]);
        break;
    }
}

/*
 * Relative error of every sampled texel and channel. Where a channel is
 * physically ~0 (night: direct light with the sun below the horizon) a
 * relative error means nothing; values below floor_fraction of the
 * channel's maximum over the samples are compared absolutely against that
 * floor instead.
 */
static double compare_samples(struct sample_job *job, double floor_fraction, const char *name)
{
    const struct sb_image *lut = &luts[job->id];
    uint32_t nc = lut->channel_count;
    double chan_max[9] = {0};
    int count = job->nx * job->ny;
    for (int k = 0; k < count; k++)
        for (uint32_t c = 0; c < nc; c++)
            chan_max[c] = fmax(chan_max[c], fabs(job->ref[k][c]));
    double worst = 0;
    int wk = 0;
    uint32_t wc = 0;
    for (int k = 0; k < count; k++) {
        int x = job->xs[k % job->nx], y = job->ys[k / job->nx];
        for (uint32_t c = 0; c < nc; c++) {
            double gpu = lut->data[((uint32_t)y * lut->width + (uint32_t)x) * nc + c];
            double ref = job->ref[k][c];
            double scale = fmax(fabs(ref), floor_fraction * chan_max[c]);
            double rel = scale > 0 ? fabs(gpu - ref) / scale : fabs(gpu);
            if (!isfinite(rel)) /* a NaN (e.g. a reference out of memory) must fail, not compare false */
                rel = INFINITY;
            if (rel > worst) {
                worst = rel;
                wk = k;
                wc = c;
            }
        }
    }
    int x = job->xs[wk % job->nx], y = job->ys[wk / job->nx];
    printf("%s: max rel error %.3g at texel (%d, %d) channel %s (gpu %.6g, ref %.6g) over %d texels\n", name, worst, x,
           y, lut->channel_names[wc], lut->data[((uint32_t)y * lut->width + (uint32_t)x) * nc + wc], job->ref[wk][wc],
           count);
    return worst;
}

static void test_sampled(enum sb_product_id id, const int *xs, int nx, const int *ys, int ny, double floor_fraction,
                         double tolerance)
{
    struct sample_job *job = calloc(1, sizeof(*job));
    job->id = id;
    memcpy(job->xs, xs, nx * sizeof(int));
    memcpy(job->ys, ys, ny * sizeof(int));
    job->nx = nx;
    job->ny = ny;
    sb_parallel_for(nx * ny, sample_texel, job);
    double worst = compare_samples(job, floor_fraction, sb_product_name(id));
    CHECK(worst <= tolerance, "%s: max relative error %.3g > %.3g", sb_product_name(id), worst, tolerance);
    free(job);
}

/*
 * Near-constant medium: scale heights of H = 1e5 km and no ozone make the
 * density exp(-h/H) = 1 - h/H + (h/H)^2/2 - ..., so along a ray of length d
 * tau = beta d (1 - <h>/H + <h^2>/(2 H^2)) with <.> the mean over the ray,
 * computed here in fp64 from the exact geometry (a 2000-step midpoint rule on
 * a smooth integrand: error < 1e-12). The neglected third-order term is below
 * (100 km / H)^3 / 6 * tau < 2e-10. Bound 1e-6 is fp32 alone: tau <= 0.91
 * (beta 4e-4 /km over 2H = 2266 km) summed from 40 samples at ~6e-8 relative
 * rounding each, plus exp.
 */
static void test_constant_medium(struct sb_vk *vk)
{
    struct sb_atmosphere_params p;
    sb_atmosphere_preset_earth(&p);
    p.rayleigh_scale_height_km = 1e5;
    p.mie_scale_height_km = 1e5;
    for (int c = 0; c < 3; c++) {
        p.ozone_absorption_per_km[c] = 0;
        p.rayleigh_scattering_per_km[c] = 1e-4 * (c + 1);
        p.mie_scattering_per_km[c] = 1e-4;
        p.mie_absorption_per_km[c] = 0;
    }
    struct sb_atmosphere_baker *baker = NULL;
    struct sb_image lut = {0};
    double ms;
    CHECK(sb_atmosphere_baker_create(vk, &p, &baker) == SB_OK, "baker");
    CHECK(sb_atmosphere_bake(baker, SB_PRODUCT_TRANSMITTANCE, NULL, &lut, NULL, &ms) == SB_OK, "bake");
    double worst = 0;
    for (uint32_t y = 0; lut.data && y < lut.height; y++)
        for (uint32_t x = 0; x < lut.width; x++) {
            double r, mu;
            sb_ref_transmittance_geometry(&p, (double)x / (lut.width - 1), (double)y / (lut.height - 1), &r, &mu);
            double top = p.top_radius_km, R = p.ground_radius_km;
            double d = -r * mu + sqrt(r * r * (mu * mu - 1) + top * top);
            double H = p.rayleigh_scale_height_km, mean_h = 0, mean_h2 = 0;
            for (int i = 0; i < 2000; i++) {
                double t = (i + 0.5) * d / 2000;
                double h = sqrt(r * r + t * t + 2 * r * mu * t) - R;
                mean_h += h / 2000;
                mean_h2 += h * h / 2000;
            }
            for (int c = 0; c < 3; c++) {
                double beta = p.rayleigh_scattering_per_km[c] + p.mie_scattering_per_km[c];
                double expect = exp(-beta * d * (1 - mean_h / H + mean_h2 / (2 * H * H)));
                double rel = fabs(lut.data[(y * lut.width + x) * 3 + c] / expect - 1);
                worst = fmax(worst, rel);
            }
        }
    printf("constant medium: transmittance max rel error %.3g against the series expansion\n", worst);
    CHECK(worst <= 1e-6, "constant medium: %.3g", worst);
    sb_image_finish(&lut);
    sb_atmosphere_baker_destroy(&baker);
}

/* ---- the fp64 reference's direction quadratures, against a plain product rule ---- */

/*
 * sb_ref_irradiance_ground and _sky integrate single scattering over
 * directions on two grids: one fixed to the zenith and, for Mie's peak, a
 * cap around the sun or the anti-sun. Here both are checked against a grid
 * that shares nothing with them: Gauss-Legendre in s with mu = mu_h +- s^2
 * on each side of the horizon (the ray integral goes like sqrt(mu - mu_h)
 * there) times the midpoint rule in azimuth, over the single-scattering
 * radiance sb_ref_sky_radiance gives for each direction. With g up to 0.9
 * (the peak 0.1 rad wide) that rule converges; its own error is measured by
 * halving both node counts. The bound, 2e-4, is a fifth of the 1e-3 the
 * baked products are held to against this reference. Measured: 1e-9 over
 * the hemisphere, up to 1e-4 over the sphere with the cap (g -0.9), whose
 * smoothstep window the zenith grid integrates at the default 32 x 16; with
 * the window at 0.3 to 0.6 rad instead of 0.5 to 1 rad it was 6.6e-4.
 */
#define BRUTE_MU 96
#define BRUTE_PHI 256

struct brute_job {
    const struct sb_atmosphere_params *p;
    double h, mu_s;
    bool whole_sphere;
    int n_mu, n_phi;
    double row[2 * BRUTE_MU][3];
};

static void brute_row(void *user, int i)
{
    struct brute_job *job = user;
    const struct sb_atmosphere_params *p = job->p;
    double R = p->ground_radius_km, r = R + job->h;
    double mu_h = job->whole_sphere ? -sqrt(1 - (R / r) * (R / r)) : 0.0;
    double s[BRUTE_MU], ws[BRUTE_MU];
    sb_ref_gauss_legendre(job->n_mu, 0, 1, s, ws);
    int k = i % job->n_mu;
    bool below = i >= job->n_mu;
    double range = below ? mu_h + 1 : 1 - mu_h;
    double mu = below ? mu_h - range * s[k] * s[k] : mu_h + range * s[k] * s[k], w_mu = range * 2 * s[k] * ws[k];
    double sin_v = sqrt(fmax(1 - mu * mu, 0.0)), sin_s = sqrt(1 - job->mu_s * job->mu_s);
    memset(job->row[i], 0, sizeof(job->row[i]));
    for (int j = 0; j < job->n_phi; j++) {
        double phi = M_PI * (j + 0.5) / job->n_phi, l[3];
        double nu = fmax(-1.0, fmin(1.0, sin_v * sin_s * cos(phi) + mu * job->mu_s));
        sb_ref_sky_radiance(p, job->h, mu, job->mu_s, nu, NULL, NULL, NULL, NULL, l);
        double w = w_mu * 2 * M_PI / job->n_phi * (job->whole_sphere ? 1 / (4 * M_PI) : mu);
        for (int c = 0; c < 3; c++)
            job->row[i][c] += w * l[c];
    }
}

static void brute_integral(struct brute_job *job, int n_mu, int n_phi, double out[3])
{
    job->n_mu = n_mu;
    job->n_phi = n_phi;
    int rows = (job->whole_sphere ? 2 : 1) * n_mu;
    sb_parallel_for(rows, brute_row, job);
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i < rows; i++)
        for (int c = 0; c < 3; c++)
            out[c] += job->row[i][c];
}

static void test_reference_directions(void)
{
    static const struct {
        double g, h, mu_s;
        bool whole_sphere;
    } cases[] = {
        {0.8, 0, 0.5, false}, {0.8, 8, 0.05, false}, {-0.8, 0, 0.3, false}, {0.9, 0, 0.5, true},
        {0.9, 8, 0.05, true}, {-0.9, 3, 0.2, true},  {0.8, 8, 0.05, true},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        struct sb_atmosphere_params p = earth;
        p.mie_g = cases[i].g;
        for (int c = 0; c < 3; c++) /* Mie's share up, so its peak counts */
            p.mie_scattering_per_km[c] *= 4;
        struct brute_job *job = calloc(1, sizeof(*job));
        *job =
            (struct brute_job){.p = &p, .h = cases[i].h, .mu_s = cases[i].mu_s, .whole_sphere = cases[i].whole_sphere};
        double fine[3], coarse[3], ref[9], direct[3];
        brute_integral(job, BRUTE_MU, BRUTE_PHI, fine);
        brute_integral(job, BRUTE_MU / 2, BRUTE_PHI / 2, coarse);
        if (cases[i].whole_sphere) {
            sb_ref_irradiance_sky(&p, cases[i].h, cases[i].mu_s, NULL, NULL, NULL, ref);
            for (int c = 0; c < 3; c++)
                ref[c] += ref[3 + c]; /* Rayleigh and Mie */
        } else {
            sb_ref_irradiance_ground(&p, cases[i].h, cases[i].mu_s, NULL, NULL, direct, ref);
        }
        double worst = 0, own = 0;
        for (int c = 0; c < 3; c++) {
            worst = fmax(worst, fabs(ref[c] / fine[c] - 1));
            own = fmax(own, fabs(coarse[c] / fine[c] - 1));
        }
        printf("%s, g %+.1f, %.0f km, sun cosine %.2f: fp64 quadrature %.3g from the product rule "
               "(which moves %.3g at half its nodes)\n",
               cases[i].whole_sphere ? "irradiance_sky" : "irradiance_ground", cases[i].g, cases[i].h, cases[i].mu_s,
               worst, own);
        CHECK(own <= 2e-4, "the product rule is not converged: %.3g", own);
        CHECK(worst <= 2e-4, "%s at g %.1f, %.0f km, mu_s %.2f: %.3g from the product rule",
              cases[i].whole_sphere ? "irradiance_sky" : "irradiance_ground", cases[i].g, cases[i].h, cases[i].mu_s,
              worst);
        free(job);
    }
}

/*
 * Direction counts far above the defaults must integrate every direction:
 * on lavapipe one pass of them would exceed llvmpipe's loop budget and
 * silently return short sums (sphere.glsl splits them into passes). The
 * defaults (8 x 8) are within 1.5e-4 of 32 x 32 here (lavapipe and the
 * H100), their error against fp64, so the two bakes agree far within 1e-3
 * unless directions went missing.
 */
static void test_many_directions(struct sb_atmosphere_baker *baker)
{
    struct sb_image many;
    struct sb_atmosphere_settings s = {.directions_mu = 32, .directions_phi = 32};
    double ms;
    enum sb_result res = sb_atmosphere_bake(baker, SB_PRODUCT_IRRADIANCE_GROUND, &s, &many, NULL, &ms);
    CHECK(res == SB_OK, "irradiance_ground at 32 x 32 directions: %s", sb_result_name(res));
    if (res)
        return;
    const struct sb_image *base = &luts[SB_PRODUCT_IRRADIANCE_GROUND];
    size_t n = sb_image_float_count(base);
    double peak = 0, worst = 0;
    for (size_t i = 0; i < n; i++)
        peak = fmax(peak, fabs(base->data[i]));
    for (size_t i = 0; i < n; i++) {
        double a = base->data[i], b = many.data[i];
        worst = fmax(worst, fabs(a - b) / fmax(fabs(b), 1e-3 * peak));
    }
    printf("irradiance_ground at 32 x 32 directions against the defaults: max rel difference %.3g\n", worst);
    CHECK(worst < 2e-4, "irradiance_ground at 32 x 32 directions differs from the defaults by %.3g", worst);
    sb_image_finish(&many);
}

/*
 * Hillaire's rule (the bench's anchor) walks every SB_ANCHOR_THREADS-th
 * direction in an invocation: past SB_ANCHOR_MAX_ITERATIONS steps an
 * invocation llvmpipe's loop budget would cut its sums short, so a setting
 * one step over is refused before it bakes, though its direction and step
 * counts are each within their own bounds.
 */
static void test_anchor_limits(struct sb_atmosphere_baker *baker)
{
    struct sb_image img = {0};
    struct sb_atmosphere_settings s = {
        .quadrature = SB_QUADRATURE_UNIFORM_0_3, .directions_mu = 64, .directions_phi = 64};
    s.samples = SB_ANCHOR_MAX_ITERATIONS / SB_ANCHOR_ITERATIONS(64 * 64, 1) + 1;
    CHECK(64 * 64 <= SB_ANCHOR_MAX_DIRECTIONS && s.samples <= SB_UNIFORM_MAX_STEPS, "the setting's own bounds");
    enum sb_result res = sb_atmosphere_bake(baker, SB_PRODUCT_MULTISCATTERING, &s, &img, NULL, NULL);
    CHECK(res == SB_ERR_USAGE, "Hillaire's rule one step over the limit: %s", sb_result_name(res));
    sb_image_finish(&img);
}

/*
 * The kernels laid out for a GPU (wider workgroups, the multiscattering LUT
 * read from its buffer) and for a CPU device (narrower, the LUT copied to
 * workgroup memory) must compute the same sums: both bake each scattering
 * product on this device, at a sixteenth of its texels, and agree to
 * within fp32's rounding of ~1e3 positive terms summed in another order
 * (a few 1e-7; the bound leaves a factor 10 to 30), where a texel's
 * directions weigh ~1e-3 of it each on average. The products go in reverse
 * bake order: a bake at another resolution is a measurement and drops the
 * product's lookup, which the products baked after it read. Where the GPU
 * layout sums in the CPU layout's order, a CPU device (llvmpipe, which
 * contracts no multiply-add of its own accord) must give the same bits.
 */
static void test_kernel_layouts(struct sb_vk *vk, struct sb_atmosphere_baker *baker)
{
    /* multiscattering twice: at its default, 16 zenith nodes a piece, and
     * at 12 x 4, 12 a piece, so that a texel's direction count is no
     * multiple of the CPU layout's 64 invocations */
    static const struct {
        enum sb_product_id id;
        uint32_t directions_mu, directions_phi; /* 0: the default */
    } cases[] = {
        {SB_PRODUCT_IRRADIANCE_SKY, 0, 0},
        {SB_PRODUCT_IRRADIANCE_GROUND, 0, 0},
        {SB_PRODUCT_MULTISCATTERING, 0, 0},
        {SB_PRODUCT_MULTISCATTERING, 12, 4},
    };
    if (sb_atmosphere_baker_set_kernels(baker, SB_ATMOSPHERE_KERNELS_CPU) == SB_ERR_DEVICE_LIMIT) {
        printf("kernel layouts: this device lacks the CPU layout's workgroup memory; not compared\n");
        return;
    }
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        enum sb_product_id id = cases[i].id;
        const struct sb_product_format *format = sb_product_format(id);
        struct sb_atmosphere_settings s = sb_atmosphere_product(id)->defaults;
        s.width = format->width / 4;
        s.height = format->height / 4;
        if (cases[i].directions_mu) {
            s.directions_mu = cases[i].directions_mu;
            s.directions_phi = cases[i].directions_phi;
        }
        struct sb_image cpu = {0}, gpu = {0};
        sb_atmosphere_baker_set_kernels(baker, SB_ATMOSPHERE_KERNELS_CPU);
        enum sb_result rc = sb_atmosphere_bake(baker, id, &s, &cpu, NULL, NULL);
        sb_atmosphere_baker_set_kernels(baker, SB_ATMOSPHERE_KERNELS_GPU);
        enum sb_result rg = sb_atmosphere_bake(baker, id, &s, &gpu, NULL, NULL);
        CHECK(rc == SB_OK && rg == SB_OK, "%s in both layouts: %s, %s", sb_product_name(id), sb_result_name(rc),
              sb_result_name(rg));
        if (rc == SB_OK && rg == SB_OK) {
            double worst = 0, peak = 0;
            size_t n = sb_image_float_count(&cpu);
            for (size_t k = 0; k < n; k++)
                peak = fmax(peak, fabs(cpu.data[k]));
            for (size_t k = 0; k < n; k++)
                worst = fmax(worst, fabs(gpu.data[k] - cpu.data[k]) / fmax(fabs(cpu.data[k]), 1e-6 * peak));
            printf("%s %ux%u, GPU against CPU kernel layout: max rel difference %.3g over %zu values\n",
                   sb_product_name(id), s.directions_mu, s.directions_phi, worst, n);
            CHECK(worst <= 1e-5, "%s: the two kernel layouts differ by %.3g", sb_product_name(id), worst);
            if (sb_atmosphere_kernels_same_order(id) && vk->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU)
                CHECK(worst == 0, "%s: the layouts sum in the same order, yet differ on a CPU device",
                      sb_product_name(id));
        }
        sb_image_finish(&cpu);
        sb_image_finish(&gpu);
    }
}

/* The spectral products (spectral.h): each of the 12 wavelengths of the
 * transmittance and the ground's irradiance held, as the three-channel
 * bakes are, to the fp64 reference of the scene at that wavelength, which
 * also proves the channels' order. */
static void test_spectral(struct sb_vk *vk)
{
    struct sb_spectral *spectral = NULL;
    CHECK(sb_spectral_create(vk, &earth, &spectral) == SB_OK, "the bands' bakers");
    static const enum sb_product_id ids[] = {SB_PRODUCT_SPECTRAL_TRANSMITTANCE, SB_PRODUCT_SPECTRAL_IRRADIANCE_GROUND};
    for (size_t i = 0; spectral && i < sizeof(ids) / sizeof(ids[0]); i++) {
        struct sb_image image = {0};
        CHECK(sb_spectral_bake(spectral, ids[i], &image, NULL, NULL) == SB_OK, "baking %s", sb_product_name(ids[i]));
        if (!image.data)
            continue;
        enum sb_product_id base = sb_spectral_base(ids[i]);
        double worst = 0;
        for (int b = 0; b < SB_SPECTRAL_BANDS; b++) {
            const struct sb_atmosphere_params *p = sb_spectral_band_params(spectral, b);
            struct sb_image inputs[SB_PRODUCT_COUNT] = {{0}}, band = {0};
            for (enum sb_product_id d = SB_PRODUCT_TRANSMITTANCE; d < base; d++) {
                const struct sb_image *lut;
                CHECK(sb_spectral_band_lut(spectral, b, d, &lut, NULL) == SB_OK, "band %d's %s", b, sb_product_name(d));
                inputs[d] = *lut; /* borrowed */
            }
            CHECK(sb_spectral_band_image(&image, base, b, &band) == SB_OK, "band %d of %s", b, sb_product_name(ids[i]));
            struct sb_accuracy_ref *ref = NULL;
            struct sb_error e = {0};
            CHECK(sb_accuracy_ref_create(p, base, 0, 0, 0, inputs, &ref) == SB_OK, "band %d's reference", b);
            if (ref)
                sb_accuracy_measure(ref, &band, false, &e);
            sb_accuracy_ref_destroy(&ref);
            printf("%s, %g to %g nm: max rel error %.3g against fp64\n", sb_product_name(ids[i]), sb_spectral_nm(3 * b),
                   sb_spectral_nm(3 * b + 2), e.max_rel);
            worst = fmax(worst, e.max_rel);
            sb_image_finish(&band);
        }
        /* the three-channel products' bounds: 1e-5 and 1e-3 (above) */
        double bound = base == SB_PRODUCT_TRANSMITTANCE ? 1e-5 : 1e-3;
        CHECK(worst <= bound, "%s at every wavelength: %.3g (bound %g)", sb_product_name(ids[i]), worst, bound);
        CHECK(sb_image_find_nonfinite(&image) < 0, "%s is finite", sb_product_name(ids[i]));
        sb_image_finish(&image);
    }
    sb_spectral_destroy(&spectral);
}

int main(void)
{
    sb_atmosphere_preset_earth(&earth);
    test_reference_directions();
    struct sb_vk *vk = NULL;
    enum sb_result res = test_vulkan(false, &vk);
    if (res == SB_ERR_NO_DEVICE)
        return test_no_device();
    if (res)
        return test_finish("atmosphere");
    struct sb_atmosphere_baker *baker = NULL;
    CHECK(sb_atmosphere_baker_create(vk, &earth, &baker) == SB_OK, "baker");
    for (int p = 0; p < SB_ATMOSPHERE_PRODUCT_COUNT; p++) {
        double ms;
        res = sb_atmosphere_bake(baker, (enum sb_product_id)p, NULL, &luts[p], NULL, &ms);
        CHECK(res == SB_OK, "baking %s", sb_product_name((enum sb_product_id)p));
        CHECK(sb_image_find_nonfinite(&luts[p]) < 0, "%s holds NaN or Inf", sb_product_name((enum sb_product_id)p));
    }
    if (!test_failures) {
        test_constant_medium(vk);
        test_transmittance();
        test_spectral(vk);
        test_probe(baker);
        /*
         * The bound is 1e-3 relative against a converged fp64
         * evaluation. The reference at 32 zenith nodes a piece and 16
         * azimuth nodes moves by at most 5e-5 (multiscattering) and 1.6e-4
         * (irradiance_sky, twilight, azimuth) when either doubles, measured
         * at the worst texels. Texels include the twilight band (x = 13..17:
         * the sun within 10 degrees of the horizon). Values below 1e-3 of
         * the channel's maximum are compared absolutely against that floor,
         * since a relative error of ~0 (night) means nothing.
         */
        static const int ms_x[] = {0, 5, 10, 13, 14, 15, 16, 17, 20, 25, 31}, ms_y[] = {0, 1, 4, 10, 20, 28, 31};
        test_sampled(SB_PRODUCT_MULTISCATTERING, ms_x, 11, ms_y, 7, 1e-3, 1e-3);
        static const int ig_x[] = {0, 16, 26, 27, 28, 29, 30, 31, 32, 33, 36, 45, 63}, ig_y[] = {0, 3, 9, 15};
        test_sampled(SB_PRODUCT_IRRADIANCE_GROUND, ig_x, 13, ig_y, 4, 1e-3, 1e-3);
        /* irradiance_sky's also either side of where its texels take a
         * quarter of the azimuths (sphere_azimuths: from x = 39 on the
         * ground, x = 44 at the top) */
        static const int is_x[] = {0, 16, 26, 27, 28, 29, 30, 31, 32, 33, 36, 40, 45, 48, 63};
        test_sampled(SB_PRODUCT_IRRADIANCE_SKY, is_x, 15, ig_y, 4, 1e-3, 1e-3);
        test_many_directions(baker);
        test_anchor_limits(baker);
        test_kernel_layouts(vk, baker); /* last: it drops the products' lookups */
    }
    sb_atmosphere_baker_destroy(&baker);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        sb_image_finish(&luts[p]);
    CHECK(sb_vk_validation_messages(vk) == 0, "%u validation messages", sb_vk_validation_messages(vk));
    sb_vk_destroy(&vk);
    return test_finish("atmosphere");
}
