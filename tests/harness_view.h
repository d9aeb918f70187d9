/*
 * What skyview's renderer tests share: the pack they render with.
 */
#ifndef SB_TEST_HARNESS_VIEW_H
#define SB_TEST_HARNESS_VIEW_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "bake.h"
#include "harness.h"
#include "pack.h"
#include "scene.h"

/* The earth's transmittance, multiple-scattering and ground-irradiance LUTs
 * (what skyview reads; irradiance_sky is not needed), baked on `vk` into
 * dir/pack and opened into `pack`; false (with the failed check recorded)
 * when either step fails. */
static inline bool test_view_pack(struct sb_vk *vk, const char *dir, const char *name, struct sb_pack *pack)
{
    char pack_dir[4200];
    snprintf(pack_dir, sizeof(pack_dir), "%s/pack", dir);
    struct sb_scene scene = {.preset = "earth"};
    snprintf(scene.name, sizeof(scene.name), "%s", name);
    sb_atmosphere_preset_earth(&scene.atmosphere);
    scene.wants[SB_PRODUCT_IRRADIANCE_GROUND] = true;
    struct sb_bake_report report;
    enum sb_result res = sb_bake_scene(vk, &scene, pack_dir, NULL, &report);
    CHECK(res == SB_OK, "bake: %s", sb_result_name(res));
    if (res)
        return false;
    res = sb_pack_open(pack_dir, pack);
    CHECK(res == SB_OK, "the pack opens: %s", sb_result_name(res));
    return res == SB_OK;
}

/*
 * Two read-back frames the renderer stored at different scales, each the
 * radiance scale (1 / the sun's largest channel) times a power of two, the
 * smaller 2^min_stops (pre-exposure, renderer.c): the scales cancel exactly,
 * so they must be the same bit for bit wherever both values are normal
 * halves at the smaller scale, and within two of its subnormal steps
 * elsewhere (a subnormal keeps fewer bits). The values that break that.
 */
static inline int test_scaled_frames_differ(const float *a, const float *b, size_t count,
                                            const double solar_irradiance[3], int min_stops)
{
    double sun_max = fmax(solar_irradiance[0], fmax(solar_irradiance[1], solar_irradiance[2]));
    double smallest = exp2(min_stops) / sun_max;
    double normal = 0x1p-14 / smallest, step = 0x1p-24 / smallest;
    int bad = 0;
    for (size_t i = 0; i < count; i++)
        if (fabs(a[i]) >= normal && fabs(b[i]) >= normal)
            bad += a[i] != b[i];
        else
            bad += fabs((double)a[i] - b[i]) > 2.0 * step;
    return bad;
}

#endif
