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
 */
#include <math.h>
#include <stdio.h>

#include "harness.h"
#include "orders_ref.h"
#include "pathtrace.h"
#include "scene.h"

#define PATHS 16384
#define GRID_ERROR 0.015

static const struct sb_orders_settings coarse = {.r = 12, .mu = 48, .mu_s = 16, .nu = 6};

static const double views[][2] = {{0, 0}, {60, 0}, {80, 180}, {87, 90}, {87, 0}, {120, 180}};
static const double suns[] = {30, 5};

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
