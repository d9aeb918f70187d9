#include "atmosphere.h"

#include <stdbool.h>
#include <stddef.h>

/*
 * The settings of each atmosphere product that a bake may choose under a
 * tolerance and that `skybake bench` sweeps, with the published methods
 * among them (the anchors). Edit a product's list here: the bake's choice
 * and the bench follow.
 */
#define HILLAIRE "Hillaire 2020 (40-step march, offset 0.3)"
#define BRUNETON "Bruneton 2017 (500-step trapezoid)"
#define HILLAIRE_MS "Hillaire 2020 (64 directions, 20-step march, LUT sun)"
#define BRUNETON_E "Bruneton 2017 (16 x 64 directions, 50-step trapezoid, LUT transmittance)"

#define GL(n, s)                                                                                                       \
    {                                                                                                                  \
        .quadrature = SB_QUADRATURE_GAUSS_LEGENDRE, .samples = n, .subdivisions = s                                    \
    }
#define UNI(rule, n)                                                                                                   \
    {                                                                                                                  \
        .quadrature = rule, .samples = n                                                                               \
    }
static const struct sb_atmosphere_candidate transmittance_sweep[] = {
    {GL(1, 1), NULL, true},
    {GL(2, 1), NULL, true},
    {GL(3, 1), NULL, true},
    {GL(4, 1), NULL, true},
    {GL(5, 1), NULL, false},
    {GL(6, 1), NULL, true},
    {GL(8, 1), NULL, true},
    {GL(4, 2), NULL, false},
    {GL(8, 2), NULL, true},
    {GL(8, 4), NULL, false},
    {GL(8, 16), NULL, false},
    {UNI(SB_QUADRATURE_UNIFORM_0_3, 10), NULL, false},
    {UNI(SB_QUADRATURE_UNIFORM_0_3, 20), NULL, false},
    {UNI(SB_QUADRATURE_UNIFORM_0_3, 40), HILLAIRE, true},
    {UNI(SB_QUADRATURE_UNIFORM_0_3, 80), NULL, false},
    {UNI(SB_QUADRATURE_UNIFORM_0_3, 160), NULL, false},
    {UNI(SB_QUADRATURE_UNIFORM_0_3, 320), NULL, false},
    {UNI(SB_QUADRATURE_MIDPOINT, 40), NULL, false},
    {UNI(SB_QUADRATURE_MIDPOINT, 160), NULL, false},
    {UNI(SB_QUADRATURE_TRAPEZOID, 100), NULL, false},
    {UNI(SB_QUADRATURE_TRAPEZOID, 500), BRUNETON, true},
    {UNI(SB_QUADRATURE_TRAPEZOID, 2000), NULL, false},
};
#define RES(w, h)                                                                                                      \
    {                                                                                                                  \
        .quadrature = SB_QUADRATURE_GAUSS_LEGENDRE, .samples = 8, .subdivisions = 1, .width = w, .height = h           \
    }
static const struct sb_atmosphere_candidate resolution_sweep[] = {
    {RES(40, 25), NULL, true},   {RES(80, 50), NULL, true},   {RES(256, 64), NULL, true},
    {RES(160, 100), NULL, true}, {RES(320, 200), NULL, true}, {RES(640, 400), NULL, false},
};
#define DIRS(m, p)                                                                                                     \
    {                                                                                                                  \
        .directions_mu = m, .directions_phi = p                                                                        \
    }
#define HILLAIRE_DIRS(n, steps)                                                                                        \
    {                                                                                                                  \
        .quadrature = SB_QUADRATURE_UNIFORM_0_3, .samples = steps, .directions_mu = n, .directions_phi = n             \
    }
static const struct sb_atmosphere_candidate multiscattering_sweep[] = {
    {HILLAIRE_DIRS(8, 20), HILLAIRE_MS, true},
    {HILLAIRE_DIRS(8, 80), NULL, false},
    {HILLAIRE_DIRS(8, 320), NULL, false},
    /* the same method with more directions: how far they take it */
    {HILLAIRE_DIRS(16, 20), NULL, false},
    {HILLAIRE_DIRS(32, 20), NULL, false},
    {HILLAIRE_DIRS(64, 20), NULL, false},
    {HILLAIRE_DIRS(64, 80), NULL, false},
    /* zenith nodes a piece x the rings' Gauss-Legendre nodes a piece */
    {DIRS(2, 2), NULL, false},
    {DIRS(4, 3), NULL, true},
    {DIRS(8, 4), NULL, true},
    {DIRS(12, 4), NULL, false},
    {DIRS(12, 6), NULL, false},
    {DIRS(16, 4), NULL, false},
    {DIRS(16, 6), NULL, true},
    {DIRS(24, 8), NULL, false},
    {DIRS(32, 12), NULL, false},
};
#define BRUNETON_DIRS(theta, phi, steps)                                                                               \
    {                                                                                                                  \
        .quadrature = SB_QUADRATURE_TRAPEZOID, .samples = steps, .directions_mu = theta, .directions_phi = phi         \
    }
static const struct sb_atmosphere_candidate irradiance_ground_sweep[] = {
    {BRUNETON_DIRS(16, 64, 50), BRUNETON_E, true},
    {BRUNETON_DIRS(8, 32, 50), NULL, false},
    {BRUNETON_DIRS(32, 128, 50), NULL, false},
    {BRUNETON_DIRS(16, 64, 200), NULL, false},
    {DIRS(4, 4), NULL, true},
    {DIRS(6, 6), NULL, true},
    {DIRS(8, 8), NULL, true},
    {DIRS(12, 12), NULL, false},
    {DIRS(16, 16), NULL, false},
    {DIRS(24, 24), NULL, false},
};
static const struct sb_atmosphere_candidate irradiance_sky_sweep[] = {
    {DIRS(4, 4), NULL, true},    {DIRS(8, 8), NULL, true},    {DIRS(12, 12), NULL, false},
    {DIRS(16, 16), NULL, false}, {DIRS(24, 24), NULL, false},
};
#undef GL
#undef UNI
#undef RES
#undef DIRS
#undef HILLAIRE_DIRS
#undef BRUNETON_DIRS

const struct sb_atmosphere_sweep sb_atmosphere_sweeps[SB_ATMOSPHERE_SWEEP_COUNT] = {
#define S(list) list, (int)(sizeof(list) / sizeof(list[0]))
    [SB_ATMOSPHERE_SWEEP_TRANSMITTANCE] = {"transmittance", SB_PRODUCT_TRANSMITTANCE, false, S(transmittance_sweep),
                                           "texel error"},
    [SB_ATMOSPHERE_SWEEP_TRANSMITTANCE_RESOLUTION] = {"transmittance_resolution", SB_PRODUCT_TRANSMITTANCE, true,
                                                      S(resolution_sweep), "bilinear lookup error"},
    [SB_ATMOSPHERE_SWEEP_MULTISCATTERING] = {"multiscattering", SB_PRODUCT_MULTISCATTERING, false,
                                             S(multiscattering_sweep), "texel error"},
    [SB_ATMOSPHERE_SWEEP_IRRADIANCE_GROUND] = {"irradiance_ground", SB_PRODUCT_IRRADIANCE_GROUND, false,
                                               S(irradiance_ground_sweep), "texel error"},
    [SB_ATMOSPHERE_SWEEP_IRRADIANCE_SKY] = {"irradiance_sky", SB_PRODUCT_IRRADIANCE_SKY, false, S(irradiance_sky_sweep),
                                            "texel error"},
#undef S
};

int sb_atmosphere_candidates(enum sb_product_id id, struct sb_atmosphere_settings out[SB_ATMOSPHERE_MAX_CANDIDATES])
{
    int n = 0;
    for (int w = 0; w < SB_ATMOSPHERE_SWEEP_COUNT; w++) {
        if (sb_atmosphere_sweeps[w].product != id || sb_atmosphere_sweeps[w].lookup)
            continue;
        for (int i = 0; i < sb_atmosphere_sweeps[w].count && n < SB_ATMOSPHERE_MAX_CANDIDATES; i++)
            out[n++] = sb_atmosphere_sweeps[w].entries[i].settings;
    }
    /* insertion sort: stable (ties keep the sweep's order, so the choice is
     * the same on every run) and small */
    for (int i = 1; i < n; i++) {
        struct sb_atmosphere_settings v = out[i];
        int j = i - 1;
        while (j >= 0 && sb_atmosphere_settings_cost(id, &out[j]) > sb_atmosphere_settings_cost(id, &v)) {
            out[j + 1] = out[j];
            j--;
        }
        out[j + 1] = v;
    }
    return n;
}
