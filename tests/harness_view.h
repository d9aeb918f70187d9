/*
 * What skyview's renderer tests share: the pack they render with.
 */
#ifndef SB_TEST_HARNESS_VIEW_H
#define SB_TEST_HARNESS_VIEW_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "harness.h"
#include "pack.h"
#include "renderer.h"
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

/* The read-back frame after `frames` frames of `v` (the first a cut) by a
 * renderer made with `rp`, each stored at the radiance scale times 2^4 but
 * the last, at 2^last_stops (sb_view.fixed_pre_exposure); malloc'd, NULL
 * (with the failed check recorded) on failure. */
static inline float *test_render_scaled(struct sb_vk *vk, const struct sb_pack *pack, const struct sb_world *world,
                                        const struct sb_renderer_params *rp, const struct sb_view *v, int frames,
                                        int last_stops)
{
    struct sb_renderer *r = NULL;
    enum sb_result res = sb_renderer_create(vk, pack, world, rp, &r);
    for (int i = 0; i < frames && !res; i++) {
        struct sb_view f = *v;
        f.snap_exposure = i == 0;
        f.fixed_pre_exposure = true;
        f.pre_exposure_stops = i == frames - 1 ? last_stops : 4;
        res = sb_renderer_render(r, &f, i == frames - 1, NULL);
    }
    CHECK(res == SB_OK, "render at fixed scales: %s", sb_result_name(res));
    float *rgb = res ? NULL : malloc(sizeof(float) * 3 * rp->width * rp->height);
    if (rgb)
        sb_renderer_hdr(r, rgb);
    sb_renderer_destroy(&r);
    return rgb;
}

/*
 * Pre-exposure's rescaled history (renderer.c): a history is stored at its
 * frame's scale and rescaled as it is read, so `frames` frames of `v` whose
 * last jumps 5 stops up or 3 down from its history's scale (powers of two)
 * end as the frames that kept theirs (test_scaled_frames_differ's rule);
 * and one frame alone ends otherwise, so the history counts and the check
 * can fail. `what` names the history in messages.
 */
static inline void test_history_rescaled(struct sb_vk *vk, const struct sb_pack *pack, const struct sb_world *world,
                                         const struct sb_renderer_params *rp, const struct sb_view *v, int frames,
                                         const char *what)
{
    float *kept = test_render_scaled(vk, pack, world, rp, v, frames, 4);
    float *up = test_render_scaled(vk, pack, world, rp, v, frames, 9);
    float *down = test_render_scaled(vk, pack, world, rp, v, frames, 1);
    float *alone = test_render_scaled(vk, pack, world, rp, v, 1, 4);
    size_t count = 3 * (size_t)rp->width * rp->height;
    if (kept && up && down && alone) {
        const double *sun = pack->scene->atmosphere.solar_irradiance;
        int n_up = test_scaled_frames_differ(kept, up, count, sun, 4);
        int n_down = test_scaled_frames_differ(kept, down, count, sun, 1);
        CHECK(n_up == 0, "%s history across a scale 32x up: %d values differ from the frame that kept its scale", what,
              n_up);
        CHECK(n_down == 0, "%s history across a scale 8x down: %d values differ from the frame that kept its scale",
              what, n_down);
        CHECK(memcmp(kept, alone, count * sizeof(float)) != 0, "the %s history changes nothing: the check is void",
              what);
        printf("%s history rescaled: %d and %d values off across 32x up and 8x down\n", what, n_up, n_down);
    }
    free(kept);
    free(up);
    free(down);
    free(alone);
}

#endif
