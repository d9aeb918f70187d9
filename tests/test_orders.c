/*
 * Multiple scattering by orders in fp64 (baker/orders_ref.h) against the
 * path tracer (baker/pathtrace.h), which shares none of its method: views
 * of the sky and of the ground at a high and a low sun, first for orders 1
 * and 2 alone (the path tracer's max_order 2 against the reference's), then
 * for every order. Each comparison allows 5 standard errors of the path
 * tracer plus GRID_ERROR, the interpolation error of the coarse grid the
 * test computes (measured: within 1.12% for orders 1 and 2 and 1.54% for
 * every order, rms 0.39% and 0.56%, the path tracer's noise included;
 * 1.01% and 1.17% while the density was read linearly in altitude, when
 * its lift made up for a 0.3% shortfall of the higher orders), and requires the
 * standard error to be small, so that a check cannot pass by being noisy.
 * Hillaire's approximation is off by 6.5 to 27% at these suns' worst
 * views: a check at GRID_ERROR tells them apart.
 *
 * First, a view's read of a table across the sun's azimuth, where the
 * medium makes it log-trigonometric (the haze's peaked dust) and where it
 * stays linear (the earth, mars), against what each states, on a table
 * made to tell them apart; and a broad dust's grid of twice the view
 * cosines, a peaked haze's not.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "../formats/family.h" /* the formats' half (sb_product_shape), not the baker's */
#include "harness.h"
#include "orders_ref.h"
#include "pathtrace.h"
#include "physics.h"
#include "scene.h"

#define PATHS 16384
#define GRID_ERROR 0.015

static const struct sb_orders_settings coarse = {.r = 12, .mu = 48, .mu_s = 16, .nu = 6};

static const double views[][2] = {{0, 0}, {60, 0}, {80, 180}, {87, 90}, {87, 0}, {120, 180}};
static const double suns[] = {30, 5};

/* A view's read across the sun's azimuth (orders_ref.h): where Mie
 * outscatters Rayleigh, log-trigonometric through every azimuth node, exact
 * for exp(a + b cos phi + c cos 2 phi + d cos 3 phi) on 4 nodes, and kept
 * between the two nodes about phi; elsewhere linear between them (in the
 * nodes' coordinate). A table constant but for the azimuth is read at
 * random views by day. */
static double azimuth_profile(const double k[4], double phi)
{
    return exp(k[0] + k[1] * cos(phi) + k[2] * cos(2 * phi) + k[3] * cos(3 * phi));
}

static double uniform(uint64_t *state)
{
    *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*state >> 11) * 0x1p-53;
}

static void check_azimuth_reads(void)
{
    struct sb_atmosphere_params mars, earth;
    sb_atmosphere_preset_mars(&mars);
    sb_atmosphere_preset_earth(&earth);
    /* a peaked dust: data/scenes/haze.json's at g 0.87, under
     * SB_ORDERS_DELTA_M_G, whose orders are computed as they are */
    struct sb_atmosphere_params haze = earth;
    for (int c = 0; c < 3; c++)
        haze.mie_scattering_per_km[c] = 0.07992;
    haze.mie_g = 0.87;
    CHECK(sb_orders_log_azimuth(&haze) && !sb_orders_log_azimuth(&mars) && !sb_orders_log_azimuth(&earth),
          "the haze's peaked dust reads the azimuth log-trigonometrically, mars's broad dust and the earth's air "
          "linearly");
    /* and a broad dust keeps twice the view cosines (the zenith's cell),
     * which the pack's shape follows; the haze keeps the earth's */
    struct sb_scene scene = {.atmosphere = mars};
    uint32_t shape[3];
    sb_product_shape(&scene, SB_PRODUCT_ORDERS, shape);
    CHECK(sb_orders_mu_nodes(&mars) == SB_ORDERS_MU_DUST && sb_orders_mu_nodes(&earth) == SB_ORDERS_MU &&
              sb_orders_log_azimuth(&haze) && sb_orders_mu_nodes(&haze) == SB_ORDERS_MU &&
              shape[1] == SB_ORDERS_R * SB_ORDERS_MU_DUST + 1,
          "mars's orders on %d mu nodes (%u rows), the earth's on %d, the haze's on %d", sb_orders_mu_nodes(&mars),
          shape[1], sb_orders_mu_nodes(&earth), sb_orders_mu_nodes(&haze));
    /* the air and a broad dust take the sun's azimuth on twice the peaked
     * dust's nodes, close about the sun; the air its cosine on more
     * (twilight); the pack's width follows */
    uint32_t earth_shape[3], haze_shape[3];
    struct sb_scene earth_scene = {.atmosphere = earth}, haze_scene = {.atmosphere = haze};
    sb_product_shape(&earth_scene, SB_PRODUCT_ORDERS, earth_shape);
    sb_product_shape(&haze_scene, SB_PRODUCT_ORDERS, haze_shape);
    CHECK(sb_orders_nu_nodes(&earth) == SB_ORDERS_NU && sb_orders_nu_nodes(&mars) == SB_ORDERS_NU &&
              sb_orders_nu_nodes(&haze) == SB_ORDERS_NU_DUST && sb_orders_mu_s_nodes(&earth) == SB_ORDERS_MU_S &&
              sb_orders_mu_s_nodes(&mars) == SB_ORDERS_MU_S_DUST &&
              sb_orders_mu_s_nodes(&haze) == SB_ORDERS_MU_S_DUST && earth_shape[0] == SB_ORDERS_MU_S * SB_ORDERS_NU &&
              shape[0] == SB_ORDERS_MU_S_DUST * SB_ORDERS_NU &&
              haze_shape[0] == SB_ORDERS_MU_S_DUST * SB_ORDERS_NU_DUST &&
              sb_orders_azimuth_power(&earth) == SB_ORDERS_NU_POWER &&
              sb_orders_azimuth_power(&mars) == SB_ORDERS_NU_POWER && sb_orders_azimuth_power(&haze) == 1.0,
          "the earth's orders on %d x %d sun cosine and azimuth nodes at power %g (%u columns), mars's on %d x %d at "
          "%g (%u), the haze's on %d x %d at %g (%u)",
          sb_orders_mu_s_nodes(&earth), sb_orders_nu_nodes(&earth), sb_orders_azimuth_power(&earth), earth_shape[0],
          sb_orders_mu_s_nodes(&mars), sb_orders_nu_nodes(&mars), sb_orders_azimuth_power(&mars), shape[0],
          sb_orders_mu_s_nodes(&haze), sb_orders_nu_nodes(&haze), sb_orders_azimuth_power(&haze), haze_shape[0]);
    /* at g 0.99 (the haze itself) the orders are computed delta-M scaled,
     * in a medium of g 0.99 / 1.99 that scatters 2% of Mie's light: the air's
     * grid, read linearly; never at g 0.8 (the earth), 0.65 (mars) or
     * backward */
    struct sb_atmosphere_params peaked = haze, medium, backward = haze;
    peaked.mie_g = 0.99;
    backward.mie_g = -0.99;
    double share = sb_orders_medium(&peaked, &medium);
    CHECK(fabs(share - 0.9801) < 1e-12 && fabs(medium.mie_g - 0.99 / 1.99) < 1e-12 &&
              fabs(medium.mie_scattering_per_km[1] - 0.07992 * 0.0199) < 1e-12 &&
              medium.mie_absorption_per_km[1] == peaked.mie_absorption_per_km[1] && !sb_orders_log_azimuth(&peaked) &&
              sb_orders_mu_s_nodes(&peaked) == SB_ORDERS_MU_S && sb_orders_nu_nodes(&peaked) == SB_ORDERS_NU &&
              sb_orders_azimuth_power(&peaked) == SB_ORDERS_NU_POWER,
          "g 0.99's delta-M: f %g, g %g, the air's grid (%d x %d at power %g)", share, medium.mie_g,
          sb_orders_mu_s_nodes(&peaked), sb_orders_nu_nodes(&peaked), sb_orders_azimuth_power(&peaked));
    CHECK(sb_orders_medium(&earth, &medium) == 0 && sb_orders_medium(&mars, &medium) == 0 &&
              sb_orders_medium(&haze, &medium) == 0 && sb_orders_medium(&backward, &medium) == 0 &&
              medium.mie_g == -0.99,
          "no delta-M below g %g", SB_ORDERS_DELTA_M_G);
    const struct sb_orders_settings s = {.r = 16, .mu = 64, .mu_s = 24, .nu = 4};
    size_t nodes = (size_t)s.r * s.mu * s.mu_s * s.nu;
    float *table = malloc(3 * nodes * sizeof(float));
    struct sb_orders_ref *grid[2] = {sb_orders_grid_create(&haze, &s), sb_orders_grid_create(&earth, &s)};
    CHECK(table && grid[0] && grid[1], "memory");
    if (!table || !grid[0] || !grid[1])
        goto done;
    const double k[4] = {0.3, 1.7, -0.4, 0.2}, peak[4] = {100, 1, 1, 1};
    uint64_t rng = 7;
    for (int profile = 0; profile < 3; profile++) {
        /* 0: the smooth profile; 1: a node at 0 (no logarithm: linear); 2: a peak at phi = 0 */
        double node[4];
        for (int j = 0; j < 4; j++)
            node[j] = profile == 2 ? peak[j] : profile == 1 && j == 3 ? 0.0 : azimuth_profile(k, M_PI * j / 3);
        for (size_t i = 0; i < nodes; i++)
            for (int c = 0; c < 3; c++)
                table[3 * i + c] = (float)(node[i % 4] * (1 + c));
        double worst[2] = {0, 0}, far_from_line = 0;
        for (int t = 0; t < 2000; t++) {
            double h = 40 * uniform(&rng), mu = 2 * uniform(&rng) - 1;
            double mu_s = 0.15 + 0.85 * uniform(&rng), phi = M_PI * uniform(&rng);
            double nu = mu * mu_s + sqrt((1 - mu * mu) * (1 - mu_s * mu_s)) * cos(phi), f = phi * 3 / M_PI;
            int i = f < 2 ? (int)f : 2;
            double line = node[i] + (f - i) * (node[i + 1] - node[i]);
            /* the earth's nodes at pi (j / 3)^p: linear between them in their index */
            double fe = 3 * pow(phi / M_PI, 1 / SB_ORDERS_NU_POWER);
            int ie = fe < 2 ? (int)fe : 2;
            double line_earth = node[ie] + (fe - ie) * (node[ie + 1] - node[ie]);
            /* the peak: between nodes 1 and 3 its ringing is clamped to the nodes' 1; -1: within the nodes */
            double want[2] = {profile == 0 ? azimuth_profile(k, phi) : profile == 1 || i > 0 ? line : -1, line_earth};
            for (int g = 0; g < 2; g++) {
                double got[3];
                sb_orders_table_read(grid[g], table, h, mu, mu_s, nu, got);
                if (want[g] < 0) /* beside the peak: within the two nodes */
                    CHECK(got[1] >= 2 * fmin(node[0], node[1]) * (1 - 1e-6) &&
                              got[1] <= 2 * fmax(node[0], node[1]) * (1 + 1e-6),
                          "azimuth %.1f: %g outside its nodes", phi * 180 / M_PI, got[1]);
                else
                    for (int c = 0; c < 3; c++)
                        worst[g] = fmax(worst[g], fabs(got[c] / ((1 + c) * want[g]) - 1));
                if (g == 0)
                    far_from_line = fmax(far_from_line, fabs(got[0] / line - 1));
            }
        }
        printf("azimuth reads, profile %d: log-trigonometric within %.2g, linear within %.2g, %.2g off the line\n",
               profile, worst[0], worst[1], far_from_line);
        CHECK(worst[0] <= 1e-6 && worst[1] <= 1e-6, "profile %d: the reads %.3g and %.3g off what they state", profile,
              worst[0], worst[1]);
        if (profile == 0)
            CHECK(far_from_line > 0.1, "the smooth profile is %.3g off the line at most: the test tells nothing",
                  far_from_line);
    }
done:
    free(table);
    sb_orders_ref_destroy(&grid[0]);
    sb_orders_ref_destroy(&grid[1]);
}

static void compare(const char *what, const struct sb_atmosphere_params *p, const struct sb_orders_ref *ref,
                    int max_order)
{
    double worst = 0.0, sum2 = 0.0;
    int n = 0;
    for (size_t s = 0; s < sizeof(suns) / sizeof(suns[0]); s++)
        for (size_t v = 0; v < sizeof(views) / sizeof(views[0]); v++) {
            double zen = views[v][0] * M_PI / 180, az = views[v][1] * M_PI / 180, el = suns[s] * M_PI / 180;
            double mu = cos(zen), mu_s = sin(el), nu = sin(zen) * cos(el) * cos(az) + mu * mu_s, got[3];
            sb_orders_ref_sky(ref, 0.002, mu, mu_s, nu, got, NULL);
            for (int c = 0; c < 3; c++) {
                struct sb_pathtrace_view view = {0.002, mu, mu_s, nu};
                struct sb_pathtrace_params params = {.seed = 5, .paths = PATHS, .max_order = max_order};
                struct sb_pathtrace_result traced = sb_pathtrace_radiance(p, &view, c, &params);
                double rel = (got[c] - traced.radiance) / traced.radiance;
                worst = fmax(worst, fabs(rel));
                sum2 += rel * rel;
                n++;
                CHECK(traced.std_error <= 0.02 * traced.radiance, "%s: the path tracer's standard error %.3g of %.3g",
                      what, traced.std_error, traced.radiance);
                CHECK(fabs(got[c] - traced.radiance) <= 5 * traced.std_error + GRID_ERROR * traced.radiance,
                      "%s, sun %g, view (%g, %g), channel %d: %.5g against the path tracer's %.5g +- %.2g", what,
                      suns[s], views[v][0], views[v][1], c, got[c], traced.radiance, traced.std_error);
            }
        }
    printf("%s: against the path tracer, worst %.3g, rms %.3g over %d views and channels\n", what, worst,
           sqrt(sum2 / n), n);
}

int main(void)
{
    check_azimuth_reads();
    struct sb_atmosphere_params earth;
    sb_atmosphere_preset_earth(&earth);
    struct sb_orders_settings two = coarse;
    two.max_order = 2;
    struct sb_orders_ref *ref = sb_orders_ref_create(&earth, &two);
    CHECK(ref && sb_orders_ref_orders(ref) == 2, "orders 1 and 2");
    if (ref)
        compare("earth, orders 1 and 2", &earth, ref, 2);
    sb_orders_ref_destroy(&ref);
    ref = sb_orders_ref_create(&earth, &coarse);
    CHECK(ref != NULL, "every order");
    if (ref) {
        printf("earth: %d orders, the last adding %.2g\n", sb_orders_ref_orders(ref), sb_orders_ref_last_share(ref));
        CHECK(sb_orders_ref_last_share(ref) < 1e-3 && sb_orders_ref_orders(ref) >= 4,
              "the orders converge: %d, the last %.3g", sb_orders_ref_orders(ref), sb_orders_ref_last_share(ref));
        compare("earth, every order", &earth, ref, 0);
    }
    sb_orders_ref_destroy(&ref);
    return test_finish("orders");
}
