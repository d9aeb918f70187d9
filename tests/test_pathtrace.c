/*
 * The fp64 path tracer (baker/pathtrace.h) against what is known without it:
 * - single scattering looking straight up at the zenith sun, in closed form
 *   for any exponential-and-tent atmosphere: every photon crosses the same
 *   total optical depth, so L = E T_total sum_k p_k(1) tau_scattering,k;
 * - the lit ground seen through no atmosphere: albedo / pi E cos, exactly;
 * - single scattering anywhere (the horizon, twilight, the limb seen from
 *   space) against the deterministic fp64 integrator of atmosphere_ref.h;
 * - double scattering against a nested quadrature of that integrator's
 *   single scattering over the sphere at points of the view ray;
 * - every order at once by energy: with nothing absorbing (no ozone, no
 *   Mie absorption, a white ground) all the sunlight the atmosphere
 *   intercepts leaves through its top again, so the radiance leaving it,
 *   integrated over the top sphere and its directions, equals the
 *   incoming flux less what crosses the atmosphere's rim unscattered
 *   (the sun itself, which the sky leaves out) -- a "white furnace";
 * - reproducibility: the same numbers on every call and any thread.
 * Each comparison allows 5 standard errors of the path tracer (estimated
 * from 16 independent batches) plus the deterministic side's own error, and
 * requires the standard error itself to be small, so that a check cannot
 * pass by being noisy.
 */
#include <math.h>
#include <string.h>

#include "atmosphere_ref.h"
#include "harness.h"
#include "parallel.h"
#include "pathtrace.h"
#include "scene.h"

static struct sb_atmosphere_params single_scattering_only(const struct sb_atmosphere_params *p)
{
    struct sb_atmosphere_params q = *p;
    for (int c = 0; c < 3; c++)
        q.ground_albedo[c] = 0.0;
    return q;
}

/* Integral of the ozone tent over altitudes [a, b]. */
static double tent_integral(const struct sb_atmosphere_params *p, double a, double b)
{
    double c = p->ozone_center_km, w = p->ozone_half_width_km;
    /* the tent's antiderivative, from its left corner */
    double lo = c - w, sum = 0;
    double x0 = fmax(a, lo), x1 = fmin(b, c);
    if (x1 > x0)
        sum += ((x1 - lo) * (x1 - lo) - (x0 - lo) * (x0 - lo)) / (2 * w);
    x0 = fmax(a, c);
    x1 = fmin(b, c + w);
    if (x1 > x0)
        sum += ((c + w - x0) * (c + w - x0) - (c + w - x1) * (c + w - x1)) / (2 * w);
    return sum;
}

static void check_zenith(const char *name, const struct sb_atmosphere_params *atmosphere, double altitude_km)
{
    struct sb_atmosphere_params p = single_scattering_only(atmosphere);
    double h0 = altitude_km, Z = p.top_radius_km - p.ground_radius_km;
    double col_r =
        p.rayleigh_scale_height_km * (exp(-h0 / p.rayleigh_scale_height_km) - exp(-Z / p.rayleigh_scale_height_km));
    double col_m = p.mie_scale_height_km * (exp(-h0 / p.mie_scale_height_km) - exp(-Z / p.mie_scale_height_km));
    double col_o = tent_integral(&p, h0, Z), g = p.mie_g;
    double phase_r = 3.0 / (16.0 * M_PI) * 2.0;
    double phase_m = 3.0 / (8.0 * M_PI) * (1 - g * g) / (2 + g * g) * 2.0 / pow(1 + g * g - 2 * g, 1.5);
    for (int c = 0; c < 3; c++) {
        double depth = p.rayleigh_scattering_per_km[c] * col_r +
                       (p.mie_scattering_per_km[c] + p.mie_absorption_per_km[c]) * col_m +
                       p.ozone_absorption_per_km[c] * col_o;
        double exact =
            p.solar_irradiance[c] * exp(-depth) *
            (phase_r * p.rayleigh_scattering_per_km[c] * col_r + phase_m * p.mie_scattering_per_km[c] * col_m);
        struct sb_pathtrace_view view = {altitude_km, 1.0, 1.0, 1.0};
        struct sb_pathtrace_params params = {.seed = 7, .paths = 4096, .max_order = 1};
        struct sb_pathtrace_result r = sb_pathtrace_radiance(&p, &view, c, &params);
        double dev = fabs(r.radiance - exact);
        printf("zenith %s from %g km, channel %d: path traced %.9g +- %.2g, closed form %.9g (%.1f sigma)\n", name,
               altitude_km, c, r.radiance, r.std_error, exact, dev / r.std_error);
        CHECK(r.std_error <= 1e-3 * exact, "zenith %s: standard error %.3g of %.3g", name, r.std_error, exact);
        CHECK(dev <= 5 * r.std_error + 1e-12 * exact, "zenith %s channel %d: %.9g against %.9g", name, c, r.radiance,
              exact);
    }
}

static void check_bare_ground(void)
{
    struct sb_atmosphere_params p;
    sb_atmosphere_preset_earth(&p);
    for (int c = 0; c < 3; c++) {
        p.rayleigh_scattering_per_km[c] = p.mie_scattering_per_km[c] = 0.0;
        p.mie_absorption_per_km[c] = p.ozone_absorption_per_km[c] = 0.0;
        p.ground_albedo[c] = 0.1 + 0.3 * c;
        p.solar_irradiance[c] = 1.0 + c;
    }
    const double views[][4] = {
        {100.0, -1.0, 0.6, -0.6},   /* straight down */
        {100.0, -0.7, 0.6, 0.1},    /* oblique */
        {2.0, -0.05, 0.2, 0.3},     /* far, near the horizon */
        {1000.0, -0.9, -0.3, 0.35}, /* down to where the sun is up, itself below the camera's horizon */
    };
    double worst = 0;
    for (size_t i = 0; i < sizeof(views) / sizeof(views[0]); i++) {
        struct sb_pathtrace_view view = {views[i][0], views[i][1], views[i][2], views[i][3]};
        double R = p.ground_radius_km, r = R + view.altitude_km;
        double t = -r * view.mu - sqrt(r * r * (view.mu * view.mu - 1) + R * R);
        double mu_ground = (r * view.mu_s + t * view.nu) / R; /* the sun's cosine at the ground point */
        for (int c = 0; c < 3; c++) {
            double exact = p.ground_albedo[c] / M_PI * p.solar_irradiance[c] * fmax(mu_ground, 0.0);
            struct sb_pathtrace_params params = {.seed = 1, .paths = 64};
            struct sb_pathtrace_result res = sb_pathtrace_radiance(&p, &view, c, &params);
            worst = fmax(worst, fabs(res.radiance - exact) / fmax(exact, 1e-300));
            CHECK(fabs(res.radiance - exact) <= 1e-12 * fmax(exact, 1e-300),
                  "bare ground view %zu channel %d: %.17g against %.17g", i, c, res.radiance, exact);
        }
    }
    printf("bare ground: largest relative deviation %.3g over 4 views\n", worst);
}

struct single_case {
    const char *what;
    double altitude_km, mu, mu_s, nu;
    double tangent_km; /* if > 0: mu is that of the ray grazing this altitude, downward */
};

static void check_single_scattering(const char *name, const struct sb_atmosphere_params *atmosphere)
{
    struct sb_atmosphere_params p = single_scattering_only(atmosphere);
    const struct single_case cases[] = {
        {"noon, up", 0.002, 0.8, 0.9, 0.75, 0},
        {"the horizon toward the sun", 0.002, 0.01, 0.2, 0.97, 0},
        {"the horizon away from the sun", 0.002, 0.0, 0.2, -0.97, 0},
        {"twilight, sun 4 deg below", 0.002, 0.2, -0.07, 0.5, 0},
        {"from 10 km, grazing", 10.0, -0.02, 0.5, 0.3, 0},
        {"down to the ground from 50 km", 50.0, -0.5, 0.7, 0.1, 0},
        {"the limb from space", 1100.0, 0.0, 0.3, 0.4, 12.0},
        {"the ground from space", 1100.0, -0.8, 0.3, -0.4, 0},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        struct single_case k_ = cases[i], *k = &k_;
        if (k->tangent_km > 0) {
            double ratio = (p.ground_radius_km + k->tangent_km) / (p.ground_radius_km + k->altitude_km);
            k->mu = -sqrt(1 - ratio * ratio);
        }
        double ref[3];
        sb_ref_sky_radiance(&p, k->altitude_km, k->mu, k->mu_s, k->nu, NULL, NULL, NULL, NULL, ref);
        for (int c = 0; c < 3; c++) {
            struct sb_pathtrace_view view = {k->altitude_km, k->mu, k->mu_s, k->nu};
            struct sb_pathtrace_params params = {.seed = 3, .paths = 8192, .max_order = 1};
            struct sb_pathtrace_result r = sb_pathtrace_radiance(&p, &view, c, &params);
            double dev = fabs(r.radiance - ref[c]);
            CHECK(ref[c] > 0, "single %s, %s: the view sees no sky", name, k->what);
            if (c == 2)
                printf("single %s, %s: path traced %.6g +- %.2g, integrated %.6g (%.1f sigma)\n", name, k->what,
                       r.radiance, r.std_error, ref[c], dev / r.std_error);
            CHECK(r.std_error <= 3e-3 * ref[c], "single %s, %s, channel %d: standard error %.3g of %.3g", name, k->what,
                  c, r.std_error, ref[c]);
            /* the integrator is converged to ~1e-6 */
            CHECK(dev <= 5 * r.std_error + 1e-5 * ref[c], "single %s, %s, channel %d: %.9g against %.9g", name, k->what,
                  c, r.radiance, ref[c]);
        }
    }
}

/*
 * Double scattering by quadrature: the view ray from the ground at mu0
 * with the sun at mu_s in its plane (nu = cos of their angle), Rayleigh
 * only (a smooth phase function, so a product rule converges):
 * L2 = int T(0, t) sigma_r(t) int p_r(w . w') L1(x_t, w') dw' dt, with L1
 * from atmosphere_ref.h. Computed in parallel over the ray's nodes.
 */
#define L2_NODES 16
#define L2_MU 24  /* per side of the horizon */
#define L2_PHI 32 /* over [0, 2 pi) */

struct double_job {
    struct sb_atmosphere_params p;
    double mu0, mu_s, nu;
    double t[L2_NODES], w[L2_NODES];
    double inner[L2_NODES][3]; /* sigma_r int p_r L1 dw' at each node */
};

static void double_node(void *user, int i)
{
    struct double_job *job = user;
    const struct sb_atmosphere_params *p = &job->p;
    double R = p->ground_radius_km, t = job->t[i];
    /* Camera at (0, 0, R), the view in the xz plane, the sun in 3D. */
    double sv = sqrt(1 - job->mu0 * job->mu0), ss = sqrt(1 - job->mu_s * job->mu_s);
    double view[3] = {sv, 0, job->mu0};
    double cos_phi = (job->nu - job->mu0 * job->mu_s) / (sv * ss);
    double sun[3] = {ss * cos_phi, ss * sqrt(fmax(1 - cos_phi * cos_phi, 0)), job->mu_s};
    double x[3] = {t * view[0], 0, R + t * view[2]};
    double r = sqrt(x[0] * x[0] + x[2] * x[2]), h = r - R;
    double up[3] = {x[0] / r, 0, x[2] / r}, e1[3] = {up[2], 0, -up[0]}, e2[3] = {0, 1, 0};
    double mu_h = -sqrt(fmax(1 - (R / r) * (R / r), 0));
    double mus[2 * L2_MU], wmu[2 * L2_MU];
    sb_ref_gauss_legendre(L2_MU, -1, mu_h, mus, wmu);
    sb_ref_gauss_legendre(L2_MU, mu_h, 1, mus + L2_MU, wmu + L2_MU);
    double mu_s_here = sun[0] * up[0] + sun[1] * up[1] + sun[2] * up[2];
    double sum[3] = {0, 0, 0};
    struct sb_ref_quality q = {.level_steps = 1, .transmittance_subdivisions = 1};
    for (int a = 0; a < 2 * L2_MU; a++)
        for (int b = 0; b < L2_PHI; b++) {
            double phi = 2 * M_PI * (b + 0.5) / L2_PHI, s = sqrt(1 - mus[a] * mus[a]);
            double d[3];
            for (int k = 0; k < 3; k++)
                d[k] = mus[a] * up[k] + s * (cos(phi) * e1[k] + sin(phi) * e2[k]);
            double nu_d = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
            double cos_theta = d[0] * view[0] + d[1] * view[1] + d[2] * view[2];
            double l1[3];
            sb_ref_sky_radiance(p, h, mus[a], mu_s_here, nu_d, NULL, NULL, NULL, &q, l1);
            double weight = wmu[a] * 2 * M_PI / L2_PHI * 3 / (16 * M_PI) * (1 + cos_theta * cos_theta);
            for (int c = 0; c < 3; c++)
                sum[c] += weight * l1[c];
        }
    for (int c = 0; c < 3; c++)
        job->inner[i][c] = p->rayleigh_scattering_per_km[c] * exp(-h / p->rayleigh_scale_height_km) * sum[c];
}

static void check_double_scattering(void)
{
    struct double_job *job = calloc(1, sizeof(*job));
    sb_atmosphere_preset_earth(&job->p);
    job->p = single_scattering_only(&job->p);
    for (int c = 0; c < 3; c++)
        job->p.mie_scattering_per_km[c] = job->p.mie_absorption_per_km[c] = 0;
    job->mu0 = 0.3;
    job->mu_s = 0.6;
    job->nu = 0.5;
    const struct sb_atmosphere_params *p = &job->p;
    double R = p->ground_radius_km, top = p->top_radius_km;
    double t_end = -R * job->mu0 + sqrt(R * R * (job->mu0 * job->mu0 - 1) + top * top);
    /* nodes in s with t = t_end s^2: dense where the air is */
    double s[L2_NODES], ws[L2_NODES];
    sb_ref_gauss_legendre(L2_NODES, 0, 1, s, ws);
    for (int i = 0; i < L2_NODES; i++) {
        job->t[i] = t_end * s[i] * s[i];
        job->w[i] = t_end * 2 * s[i] * ws[i];
    }
    sb_parallel_for(L2_NODES, double_node, job);
    for (int c = 0; c < 3; c++) {
        double l2 = 0;
        for (int i = 0; i < L2_NODES; i++) {
            double d[3];
            sb_ref_optical_depth(p, R, job->mu0, 0, job->t[i], 2, d);
            l2 += job->w[i] * exp(-d[c]) * job->inner[i][c];
        }
        double l1[3];
        sb_ref_sky_radiance(p, 0, job->mu0, job->mu_s, job->nu, NULL, NULL, NULL, NULL, l1);
        struct sb_pathtrace_view view = {0, job->mu0, job->mu_s, job->nu};
        struct sb_pathtrace_params params = {.seed = 11, .paths = 65536, .max_order = 2};
        struct sb_pathtrace_result r = sb_pathtrace_radiance(p, &view, c, &params);
        double expected = l1[c] + l2, dev = fabs(r.radiance - expected);
        printf("double scattering, channel %d: path traced %.6g +- %.2g, quadrature %.6g (order 2 is %.1f%%; "
               "%.1f sigma)\n",
               c, r.radiance, r.std_error, expected, 100 * l2 / expected, dev / r.std_error);
        CHECK(r.std_error <= 2e-3 * expected, "double scattering: standard error %.3g of %.3g", r.std_error, expected);
        /* the nested product rule (16 x 48 x 32 nodes) moves by 1e-5 at 24 x 80 x 64 */
        CHECK(dev <= 5 * r.std_error + 1e-4 * expected, "double scattering channel %d: %.6g against %.6g", c,
              r.radiance, expected);
    }
    free(job);
}

/*
 * The furnace: Phi_out = int_top int_inward L cos dw dA against
 * Phi_in = pi top^2 E (1 - direct), direct being the fraction that crosses
 * unscattered: (2 / top^2) int_R^top T(b) b db over impact parameters b,
 * T(b) the whole chord's. With points uniform on the top sphere (the sun's
 * cosine there uniform in [-1, 1]), inward directions cosine-weighted and
 * the azimuth to the sun uniform, each sample estimates the ratio as
 * 4 pi L / E. Stratified, in independent replicas whose spread gives the
 * error.
 */
#define FURNACE_REPLICAS 8
#define FURNACE_STRATA 12 /* per dimension of (sun cosine, view cosine^2, azimuth): 1728 views a replica */

struct furnace_job {
    struct sb_atmosphere_params p;
    int channel;
    double ratio[FURNACE_REPLICAS];
};

static void furnace_replica(void *user, int k)
{
    struct furnace_job *job = user;
    const int n = FURNACE_STRATA;
    double sum = 0;
    uint64_t state = 0x9e3779b97f4a7c15ull * (uint64_t)(k + 1);
    for (int i = 0; i < n * n * n; i++) {
        double u[3];
        for (int d = 0; d < 3; d++) { /* jitter in the stratum (a 64-bit LCG is plenty here) */
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            u[d] = ((i / (d == 0 ? 1 : d == 1 ? n : n * n)) % n + (double)(state >> 11) * 0x1.0p-53) / n;
        }
        double mu_s = 2 * u[0] - 1, mu = -sqrt(u[1]), phi = 2 * M_PI * u[2];
        double nu = mu * mu_s + sqrt(1 - mu * mu) * sqrt(1 - mu_s * mu_s) * cos(phi);
        struct sb_pathtrace_view view = {job->p.top_radius_km - job->p.ground_radius_km, mu, mu_s, nu};
        struct sb_pathtrace_params params = {.seed = (uint64_t)k, .paths = 16};
        sum += sb_pathtrace_radiance(&job->p, &view, job->channel, &params).radiance;
    }
    job->ratio[k] = 4 * M_PI * sum / (n * n * n) / job->p.solar_irradiance[job->channel];
}

static void check_furnace(double g)
{
    struct furnace_job job = {0};
    sb_atmosphere_preset_earth(&job.p);
    job.p.mie_g = g;
    for (int c = 0; c < 3; c++) {
        job.p.mie_absorption_per_km[c] = job.p.ozone_absorption_per_km[c] = 0;
        job.p.ground_albedo[c] = 1;
        job.p.mie_scattering_per_km[c] *= 10; /* more orders, and the Mie sampling's weights */
    }
    job.channel = 2; /* blue: the most scattering */
    sb_parallel_for(FURNACE_REPLICAS, furnace_replica, &job);
    double mean = 0, var = 0;
    for (int k = 0; k < FURNACE_REPLICAS; k++)
        mean += job.ratio[k] / FURNACE_REPLICAS;
    for (int k = 0; k < FURNACE_REPLICAS; k++)
        var += (job.ratio[k] - mean) * (job.ratio[k] - mean) / (FURNACE_REPLICAS - 1);
    double error = sqrt(var / FURNACE_REPLICAS);
    /* b = top - (top - R) s^2, dense at the rim's inner edge */
    double R = job.p.ground_radius_km, top = job.p.top_radius_km, direct = 0, s[48], w[48];
    sb_ref_gauss_legendre(48, 0, 1, s, w);
    for (int i = 0; i < 48; i++) {
        double b = top - (top - R) * s[i] * s[i], db = (top - R) * 2 * s[i] * w[i], t[3];
        sb_ref_transmittance(&job.p, top, -sqrt(1 - (b / top) * (b / top)), 4, t);
        direct += 2 / (top * top) * t[job.channel] * b * db;
    }
    double expected = 1 - direct;
    printf("furnace, g %g: outgoing over incoming flux %.5f +- %.2g, expected %.5f (%.1f sigma)\n", g, mean, error,
           expected, fabs(mean - expected) / error);
    CHECK(error <= 3e-3, "furnace: standard error %.3g", error);
    CHECK(fabs(mean - expected) <= 5 * error, "furnace: %.5f of the flux leaves, expected %.5f", mean, expected);
}

/*
 * Drawing the next vertex's direction about the sun too (sunlight_ahead)
 * changes the noise, not the mean: the mean of every order at once is the
 * furnace's with g = 0.99, above. The noise: at order 2 beside the sun in
 * a haze of g = 0.99, where the aureole's light reaches a vertex along one
 * direction, the guided error is at most a third of the unguided one's.
 * (Their means are not compared: without guiding, the rare paths along
 * the peak make the estimate heavy-tailed, low by some percent at 8192
 * paths, and its batches' spread says less than its error.)
 */
struct guided_job {
    struct sb_atmosphere_params p;
    struct sb_pathtrace_view view;
    struct sb_pathtrace_result r[3][2]; /* channel, unguided / guided */
};

static void guided_one(void *user, int i)
{
    struct guided_job *job = user;
    struct sb_pathtrace_params params = {.seed = 3, .paths = 8192, .max_order = 2, .unguided = !(i % 2)};
    job->r[i / 2][i % 2] = sb_pathtrace_radiance(&job->p, &job->view, i / 2, &params);
}

static void check_guided(const struct sb_atmosphere_params *haze)
{
    struct guided_job job = {.p = *haze};
    double mu_s = sin(10 * M_PI / 180), mu = 0.1, phi = 8 * M_PI / 180; /* 9 degrees from the sun */
    job.view =
        (struct sb_pathtrace_view){0.002, mu, mu_s, mu * mu_s + sqrt((1 - mu * mu) * (1 - mu_s * mu_s)) * cos(phi)};
    sb_parallel_for(6, guided_one, &job);
    for (int c = 0; c < 3; c++) {
        struct sb_pathtrace_result a = job.r[c][0], b = job.r[c][1];
        printf("order 2 beside the sun, channel %d: guided %.6g +- %.2g, unguided %.6g +- %.2g\n", c, b.radiance,
               b.std_error, a.radiance, a.std_error);
        CHECK(b.std_error <= a.std_error / 3, "guided channel %d: error %.3g, unguided %.3g", c, b.std_error,
              a.std_error);
    }
}

struct repeat_job {
    struct sb_atmosphere_params p;
    struct sb_pathtrace_result r[8];
};

static void repeat_one(void *user, int i)
{
    struct repeat_job *job = user;
    struct sb_pathtrace_view view = {0.5 * i, 0.1 + 0.1 * i, 0.3, 0.2};
    struct sb_pathtrace_params params = {.seed = 5, .paths = 256};
    job->r[i] = sb_pathtrace_radiance(&job->p, &view, i % 3, &params);
}

static void check_reproducible(void)
{
    struct repeat_job a, b;
    sb_atmosphere_preset_earth(&a.p);
    b.p = a.p;
    sb_parallel_for(8, repeat_one, &a);
    for (int i = 7; i >= 0; i--)
        repeat_one(&b, i);
    CHECK(!memcmp(a.r, b.r, sizeof(a.r)), "threads and order change the path tracer's results");
    struct sb_pathtrace_view view = {0.002, 0.3, 0.5, 0.1};
    struct sb_pathtrace_params one = {.seed = 5, .paths = 256}, other = {.seed = 6, .paths = 256};
    struct sb_pathtrace_result x = sb_pathtrace_radiance(&a.p, &view, 1, &one);
    struct sb_pathtrace_result y = sb_pathtrace_radiance(&a.p, &view, 1, &other);
    CHECK(x.radiance != y.radiance, "the seed changes nothing");
    CHECK(fabs(x.radiance - y.radiance) <= 5 * hypot(x.std_error, y.std_error), "two seeds disagree: %.6g, %.6g",
          x.radiance, y.radiance);
    /* every order adds light */
    struct sb_pathtrace_params first = {.seed = 5, .paths = 256, .max_order = 1};
    struct sb_pathtrace_result s = sb_pathtrace_radiance(&a.p, &view, 1, &first);
    CHECK(x.radiance > s.radiance * 1.05, "all orders %.6g, single %.6g", x.radiance, s.radiance);
}

int main(void)
{
    struct sb_atmosphere_params earth, mars, haze;
    sb_atmosphere_preset_earth(&earth);
    sb_atmosphere_preset_mars(&mars);
    haze = earth;
    haze.mie_g = 0.99;
    for (int c = 0; c < 3; c++) {
        haze.mie_scattering_per_km[c] *= 20;
        haze.mie_absorption_per_km[c] *= 20;
    }
    check_zenith("earth", &earth, 0.0);
    check_zenith("earth", &earth, 30.0);
    check_zenith("mars", &mars, 0.0);
    check_zenith("haze", &haze, 0.0);
    check_bare_ground();
    check_single_scattering("earth", &earth);
    check_single_scattering("mars", &mars);
    check_double_scattering();
    check_furnace(0.8);
    check_furnace(0.99);
    check_guided(&haze);
    check_reproducible();
    return test_finish("pathtrace");
}
