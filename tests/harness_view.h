/*
 * What skyview's renderer tests share: the pack they render with.
 */
#ifndef SB_TEST_HARNESS_VIEW_H
#define SB_TEST_HARNESS_VIEW_H

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

#endif
