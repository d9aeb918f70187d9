/*
 * The reflection family (issue 18, docs/reflections.md): the DFG
 * (split-sum) LUT (dfg.h), which depends on nothing but its kernel; the
 * reflection probes' cubes, captured at each probe (the sky-only probe at
 * the view's altitude first, then the scene's) and prefiltered for GGX
 * roughness (reflection.h); and the probes' records, with the irradiance
 * each cube sees as order-2 SH.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "cube.h"
#include "dfg.h"
#include "exr.h"
#include "family.h"
#include "json.h"
#include "level.h"
#include "load.h"
#include "log.h"
#include "mesh.h"
#include "probes.h"
#include "reflection.h"

#define DFG_RECIPE 1
#define CUBES_RECIPE 2 /* 2: the sky's light through each texel's transfer, clamped once */
#define SURFACES_RECIPE 1
#define PROBES_RECIPE 1
/* More of a probe's view in back faces than this: inside geometry. */
#define INSIDE_FRACTION 0.25

struct reflection_state {
    bool has_world;
    const struct sb_level *level;
    char mesh_hash[SB_HASH_HEX_SIZE];
    char path[640]; /* the world's file, absolute */
    struct sb_bvh bvh;
    struct sb_raycaster *rc;
    struct sb_surfaces surfaces; /* made with rc */
    struct sb_atmosphere_baker *atmosphere;
    struct sb_reflection_kernels kernels;
    struct sb_vk *vk; /* the kernels' */
};

static bool wants_cubes(const struct sb_scene *scene)
{
    return scene->wants[SB_PRODUCT_REFLECTION_CUBES] || scene->wants[SB_PRODUCT_REFLECTION_PROBES] ||
           scene->wants[SB_PRODUCT_REFLECTION_SURFACES];
}

static enum sb_result reflection_create(struct sb_vk *vk, const struct sb_scene *scene, void **out)
{
    struct reflection_state *st = calloc(1, sizeof(*st));
    if (!st)
        return SB_ERR_NOMEM;
    *out = st;
    if (wants_cubes(scene) && !scene->has_world && scene->reflections.probe_count)
        sb_warn("reflections.probes: the scene has no world, so every cube sees the sky alone");
    if (!wants_cubes(scene) || !scene->has_world)
        return SB_OK;
    enum sb_result res = sb_level_acquire(&scene->world, scene->directory, &st->level, st->path, sizeof(st->path));
    if (res)
        return res;
    st->has_world = true;
    sb_level_hash(st->level, st->mesh_hash);
    return SB_OK;
}

static void reflection_destroy(void **state)
{
    struct reflection_state *st = *state;
    if (st) {
        if (st->vk)
            sb_reflection_kernels_destroy(st->vk, &st->kernels);
        sb_atmosphere_baker_destroy(&st->atmosphere);
        if (st->rc)
            sb_surfaces_destroy(st->rc->vk, &st->surfaces);
        sb_raycaster_destroy(&st->rc);
        sb_bvh_finish(&st->bvh);
        sb_level_release(&st->level);
    }
    free(st);
    *state = NULL;
}

static uint32_t reflection_depends_on(enum sb_product_id id)
{
    if (id == SB_PRODUCT_REFLECTION_CUBES || id == SB_PRODUCT_REFLECTION_SURFACES) /* the capture's atmosphere */
        return 1u << SB_PRODUCT_TRANSMITTANCE | 1u << SB_PRODUCT_MULTISCATTERING | 1u << SB_PRODUCT_IRRADIANCE_GROUND;
    return id == SB_PRODUCT_REFLECTION_PROBES ? 1u << SB_PRODUCT_REFLECTION_CUBES : 0;
}

static void reflection_key(void *state, const struct sb_scene *scene, enum sb_product_id id, struct sb_key_text *key)
{
    const struct reflection_state *st = state;
    const struct sb_reflection_params *p = &scene->reflections;
    char code[SB_HASH_HEX_SIZE];
    if (id == SB_PRODUCT_DFG) {
        sb_dfg_code_hash(code);
        sb_key_add(key, " recipe %d size %d samples %dx%d code %s", DFG_RECIPE, SB_DFG_SIZE, SB_DFG_SAMPLES_SIDE,
                   SB_DFG_SAMPLES_SIDE, code);
        return;
    }
    if (id == SB_PRODUCT_REFLECTION_PROBES) { /* the cubes' key is its input's */
        sb_key_add(key, " recipe %d altitude_km=%a", PROBES_RECIPE, scene->view.altitude_km);
        for (int i = 0; i < p->probe_count; i++) {
            sb_key_add3(key, "at", p->probes[i].position_m);
            sb_key_add3(key, "box_min", p->probes[i].box_m[0]);
            sb_key_add3(key, "box_max", p->probes[i].box_m[1]);
        }
        return;
    }
    sb_reflection_code_hash(code);
    if (id == SB_PRODUCT_REFLECTION_SURFACES) { /* the cubes' key without the sun, the sky and the prefilter */
        sb_key_add(key, " recipe %d face %u ambient %u world %s code %s", SURFACES_RECIPE, p->face_size,
                   p->ambient_rays, st->has_world ? st->mesh_hash : "none", code);
        if (st->has_world)
            sb_key_add(key, " bvh %d", SB_BVH_VERSION);
        for (int i = 0; i < p->probe_count; i++)
            sb_key_add3(key, "at", p->probes[i].position_m);
        return;
    }
    sb_key_add(key, " recipe %d face %u samples %u ambient %u altitude_km=%a sun=%a,%a world %s code %s", CUBES_RECIPE,
               p->face_size, p->samples, p->ambient_rays, scene->view.altitude_km, scene->view.sun_elevation_deg,
               scene->view.sun_azimuth_deg, st->has_world ? st->mesh_hash : "none", code);
    if (st->has_world)
        sb_key_add(key, " bvh %d", SB_BVH_VERSION);
    for (int i = 0; i < p->probe_count; i++)
        sb_key_add3(key, "at", p->probes[i].position_m);
}

/* Where the sun is: elevation and azimuth clockwise from north (-z), as
 * skyview has them. */
static void sun_direction(const struct sb_scene *scene, double out[3])
{
    double el = scene->view.sun_elevation_deg * M_PI / 180, az = scene->view.sun_azimuth_deg * M_PI / 180;
    out[0] = cos(el) * sin(az);
    out[1] = sin(el);
    out[2] = -cos(el) * cos(az);
}

/* Probe i's position (0: the sky-only probe at the view's altitude). */
static void probe_position(const struct sb_scene *scene, int i, double out[3])
{
    if (i == 0) {
        out[0] = out[2] = 0;
        out[1] = scene->view.altitude_km * 1e3;
    } else {
        memcpy(out, scene->reflections.probes[i - 1].position_m, 3 * sizeof(double));
    }
}

/* The capture's inputs on the device: the atmosphere's LUTs, the world's
 * BVH and surfaces (once for the family's products). */
static enum sb_result capture_inputs(struct reflection_state *st, struct sb_vk *vk, const struct sb_scene *scene,
                                     const struct sb_image baked[SB_PRODUCT_COUNT])
{
    enum sb_result res = SB_OK;
    double t0 = 1e3 * sb_now_s();
    if (!st->atmosphere) {
        static const enum sb_product_id inputs[] = {SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_MULTISCATTERING,
                                                    SB_PRODUCT_IRRADIANCE_GROUND};
        res = sb_atmosphere_baker_create(vk, &scene->atmosphere, &st->atmosphere);
        for (size_t i = 0; i < sizeof(inputs) / sizeof(inputs[0]) && !res; i++)
            res = sb_atmosphere_adopt(st->atmosphere, inputs[i], &baked[inputs[i]]);
    }
    if (!res && st->has_world && !st->rc && !(res = sb_level_build_bvh(st->level, &st->bvh)) &&
        !(res = sb_raycaster_create(vk, &st->bvh, &st->rc)))
        res = sb_surfaces_create_level(vk, st->level, &st->surfaces);
    if (!res)
        sb_debug("reflections: the atmosphere's LUTs and the BVH on the device in %.1f ms", 1e3 * sb_now_s() - t0);
    st->vk = vk;
    return res;
}

/* Cube i's level 0 (and its surfaces, when not NULL) captured at its
 * probe (0: the sky-only probe at the view's altitude, the sky alone). */
static enum sb_result capture_probe(struct reflection_state *st, struct sb_vk *vk, const struct sb_scene *scene,
                                    uint32_t i, struct sb_capture_params *cp, float *level0, float *surfaces,
                                    double *ms)
{
    double at[3];
    probe_position(scene, (int)i, at);
    for (int k = 0; k < 3; k++)
        cp->origin_m[k] = (float)at[k];
    cp->altitude_km = fmax(at[1], 0.0) * 1e-3;
    struct sb_capture_inputs in = {
        .atmosphere = st->atmosphere, .rc = i ? st->rc : NULL, .surfaces = &st->surfaces, .kernels = &st->kernels};
    return sb_reflection_capture(vk, &in, cp, level0, surfaces, ms);
}

static enum sb_result bake_cubes(struct reflection_state *st, struct sb_vk *vk, const struct sb_scene *scene,
                                 const struct sb_image baked[SB_PRODUCT_COUNT], struct sb_image *image,
                                 struct sb_artifact *a)
{
    const struct sb_reflection_params *p = &scene->reflections;
    uint32_t n = p->face_size, levels = sb_cube_levels(n), cubes = 1 + (uint32_t)p->probe_count;
    enum sb_result res = capture_inputs(st, vk, scene, baked);
    if (res)
        return res;
    uint64_t chain = sb_cube_level_offset(n, levels);
    float *level0 = malloc((size_t)6 * n * n * 4 * sizeof(float));
    float *filtered = malloc(chain * 4 * sizeof(float));
    if (!level0 || !filtered || (res = sb_image_init_levels(image, n, 6 * n, cubes, 3, levels))) {
        res = res ? res : SB_ERR_NOMEM;
        goto done;
    }
    sb_image_set_channel_names(image, "R,G,B");
    struct sb_capture_params cp = {.face_size = n, .ambient_rays = p->ambient_rays};
    sun_direction(scene, cp.sun);
    double gpu_ms = 0, worst_back = 0;
    for (uint32_t i = 0; i < cubes && !res; i++) {
        double at[3], ms = 0;
        probe_position(scene, (int)i, at);
        double t1 = 1e3 * sb_now_s();
        if ((res = capture_probe(st, vk, scene, i, &cp, level0, NULL, &ms)))
            break;
        sb_debug("reflection_cubes: probe %u captured in %.1f ms (%.3f ms on the device)", i, 1e3 * sb_now_s() - t1,
                 ms);
        gpu_ms += ms;
        if (i == 0) /* the sky the surfaces of the other probes are lit by */
            sb_reflection_sh(level0, n, 0, cp.sky_sh);
        double back = 0;
        for (size_t t = 0; t < (size_t)6 * n * n; t++)
            back += level0[4 * t + 3];
        back /= 6.0 * n * n;
        worst_back = fmax(worst_back, back);
        if (back > INSIDE_FRACTION) {
            sb_error("reflections.probes[%u] at (%g, %g, %g) is inside geometry: %.0f%% of what it sees is back "
                     "faces; move it into free space",
                     i - 1, at[0], at[1], at[2], 100 * back);
            res = SB_ERR_OUT_OF_RANGE;
            break;
        }
        const struct sb_prefilter_params pp = {.samples = p->samples, .kernels = &st->kernels};
        t1 = 1e3 * sb_now_s();
        if ((res = sb_reflection_prefilter(vk, level0, n, &pp, filtered, &ms)))
            break;
        sb_debug("reflection_cubes: probe %u prefiltered in %.1f ms (%.3f ms on the device)", i, 1e3 * sb_now_s() - t1,
                 ms);
        gpu_ms += ms;
        for (uint32_t l = 0; l < levels; l++) {
            uint32_t m = n >> l;
            const float *src = filtered + 4 * sb_cube_level_offset(n, l);
            float *dst = image->data + sb_image_level_offset(image, l) + (size_t)i * 6 * m * m * 3;
            for (size_t t = 0; t < (size_t)6 * m * m; t++)
                memcpy(&dst[3 * t], &src[4 * t], 3 * sizeof(float));
        }
        sb_info("reflection_cubes: probe %u of %u", i + 1, cubes);
    }
    if (res)
        goto done;
    a->gpu_ms = gpu_ms;
    snprintf(a->settings_json, sizeof(a->settings_json),
             "{\"face_size\":%u,\"levels\":%u,\"cubes\":%u,\"samples\":%u,\"ambient_rays\":%u,"
             "\"roughness\":\"l/(levels-1)=r(2-r)\",\"sun_disk\":\"analytic at runtime\",\"most_back_faces\":%.4f}",
             n, levels, cubes, p->samples, p->ambient_rays, worst_back);
    if (st->has_world)
        sb_artifact_set_world(a, st->mesh_hash, st->path);
done:
    if (res)
        sb_image_finish(image);
    free(level0);
    free(filtered);
    return res;
}

/*
 * What relights the cubes (docs/pack.md): each cube's level 0 captured
 * again, its surfaces kept (albedo, distance, normal toward the probe, the
 * sky's transfer); the levels below are means of 2 x 2 texels (OpenEXR's
 * cube chain; a runtime reads level 0). Nothing in it depends on the sun.
 */
static enum sb_result bake_surfaces(struct reflection_state *st, struct sb_vk *vk, const struct sb_scene *scene,
                                    const struct sb_image baked[SB_PRODUCT_COUNT], struct sb_image *image,
                                    struct sb_artifact *a)
{
    const struct sb_reflection_params *p = &scene->reflections;
    uint32_t n = p->face_size, levels = sb_cube_levels(n), cubes = 1 + (uint32_t)p->probe_count;
    const uint32_t channels = 4 * SB_RELIGHT_VEC4S;
    enum sb_result res = capture_inputs(st, vk, scene, baked);
    if (res)
        return res;
    float *level0 = malloc((size_t)6 * n * n * 4 * sizeof(float));
    float *surfaces = malloc((size_t)6 * n * n * channels * sizeof(float));
    if (!level0 || !surfaces || (res = sb_image_init_levels(image, n, 6 * n, cubes, channels, levels))) {
        res = res ? res : SB_ERR_NOMEM;
        goto done;
    }
    sb_image_set_channel_names(image, sb_product_format(SB_PRODUCT_REFLECTION_SURFACES)->channel_names);
    struct sb_capture_params cp = {.face_size = n, .ambient_rays = p->ambient_rays};
    sun_direction(scene, cp.sun);
    double gpu_ms = 0;
    for (uint32_t i = 0; i < cubes && !res; i++) {
        double ms = 0;
        if ((res = capture_probe(st, vk, scene, i, &cp, level0, surfaces, &ms)))
            break;
        gpu_ms += ms;
        /* the GPU's vec4s are the channels in order (config.h) */
        memcpy(image->data + (size_t)i * 6 * n * n * channels, surfaces, (size_t)6 * n * n * channels * sizeof(float));
        for (uint32_t l = 1; l < levels; l++) {
            uint32_t m = n >> l;
            const float *src = image->data + sb_image_level_offset(image, l - 1) + (size_t)i * 6 * 4 * m * m * channels;
            float *dst = image->data + sb_image_level_offset(image, l) + (size_t)i * 6 * m * m * channels;
            for (uint32_t f = 0; f < 6; f++)
                for (uint32_t y = 0; y < m; y++)
                    for (uint32_t x = 0; x < m; x++)
                        for (uint32_t c = 0; c < channels; c++) {
                            const float *q = src + (((size_t)f * 2 * m + 2 * y) * 2 * m + 2 * x) * channels + c;
                            size_t row = (size_t)2 * m * channels;
                            double sum = (double)q[0] + q[channels] + q[row] + q[row + channels];
                            dst[(((size_t)f * m + y) * m + x) * channels + c] = (float)(0.25 * sum);
                        }
        }
        sb_info("reflection_surfaces: probe %u of %u", i + 1, cubes);
    }
    if (res)
        goto done;
    a->gpu_ms = gpu_ms;
    snprintf(a->settings_json, sizeof(a->settings_json),
             "{\"face_size\":%u,\"cubes\":%u,\"ambient_rays\":%u,\"transfer\":\"order-2 SH of the clamped cosine "
             "over the escaping directions: E_sky = sum_k T_k L_k\",\"levels\":\"means of 2x2 (level 0 is read)\"}",
             n, cubes, p->ambient_rays);
    if (st->has_world)
        sb_artifact_set_world(a, st->mesh_hash, st->path);
done:
    if (res)
        sb_image_finish(image);
    free(level0);
    free(surfaces);
    return res;
}

static enum sb_result bake_probes(const struct sb_scene *scene, const struct sb_image *cubes, struct sb_image *image,
                                  struct sb_artifact *a)
{
    uint32_t count = cubes->depth, n = cubes->width;
    if (count != 1 + (uint32_t)scene->reflections.probe_count) {
        sb_error("reflection_probes: the cubes hold %u probes, the scene %d", count,
                 1 + scene->reflections.probe_count);
        return SB_ERR_BAD_IMAGE;
    }
    float *level0 = malloc((size_t)6 * n * n * 4 * sizeof(float));
    enum sb_result res = level0 ? sb_image_init(image, count, 1, SB_REFLECTION_PROBES_CHANNEL_COUNT) : SB_ERR_NOMEM;
    if (res) {
        free(level0);
        return res;
    }
    sb_image_set_channel_names(image, SB_REFLECTION_PROBES_CHANNELS);
    for (uint32_t i = 0; i < count; i++) {
        const float *src = cubes->data + (size_t)i * 6 * n * n * 3;
        for (size_t t = 0; t < (size_t)6 * n * n; t++) {
            memcpy(&level0[4 * t], &src[3 * t], 3 * sizeof(float));
            level0[4 * t + 3] = 0;
        }
        double sh[9][3], at[3];
        sb_reflection_sh(level0, n, 1, sh);
        probe_position(scene, (int)i, at);
        float *o = &image->data[(size_t)i * SB_REFLECTION_PROBES_CHANNEL_COUNT];
        for (int k = 0; k < 3; k++) {
            o[k] = (float)at[k];
            o[3 + k] = i ? (float)scene->reflections.probes[i - 1].box_m[0][k] : 0.0f;
            o[6 + k] = i ? (float)scene->reflections.probes[i - 1].box_m[1][k] : 0.0f;
        }
        for (int k = 0; k < 9; k++)
            for (int c = 0; c < 3; c++)
                o[9 + 3 * k + c] = (float)sh[k][c];
    }
    free(level0);
    a->probes = (struct sb_probe_layout){.explicit_count = count, .ray_count = 6 * n * n};
    snprintf(a->settings_json, sizeof(a->settings_json),
             "{\"probes\":%u,\"irradiance\":\"order-2 SH of each cube's level 0 (exact texel solid angles), "
             "cosine-convolved\",\"first\":\"the sky-only probe at the view's altitude (box zero: everywhere)\"}",
             count);
    return SB_OK;
}

static enum sb_result reflection_bake(void *state, struct sb_vk *vk, const struct sb_scene *scene,
                                      enum sb_product_id id, const struct sb_image baked[SB_PRODUCT_COUNT],
                                      struct sb_image *image, struct sb_artifact *a)
{
    if (id == SB_PRODUCT_REFLECTION_CUBES)
        return bake_cubes(state, vk, scene, baked, image, a);
    if (id == SB_PRODUCT_REFLECTION_PROBES)
        return bake_probes(scene, &baked[SB_PRODUCT_REFLECTION_CUBES], image, a);
    if (id == SB_PRODUCT_REFLECTION_SURFACES)
        return bake_surfaces(state, vk, scene, baked, image, a);
    enum sb_result res = sb_dfg_bake(vk, image, &a->gpu_ms);
    if (!res)
        snprintf(a->settings_json, sizeof(a->settings_json),
                 "{\"brdf\":\"GGX, height-correlated Smith, Schlick\",\"x\":\"Fresnel-weighted\",\"y\":\"whole\","
                 "\"samples\":[%d,%d],\"sampling\":\"midpoint grid of the inverse CDF of D(h) (n.h)\"}",
                 SB_DFG_SAMPLES_SIDE, SB_DFG_SAMPLES_SIDE);
    return res;
}

static uint32_t reflection_kernels(void *state, const struct sb_scene *scene, enum sb_product_id id,
                                   struct sb_pipeline_params out[SB_FAMILY_KERNELS_MAX])
{
    const struct reflection_state *st = state;
    uint32_t n = 0;
    if (id == SB_PRODUCT_DFG)
        out[n++] = sb_dfg_kernel();
    if (id != SB_PRODUCT_REFLECTION_CUBES && id != SB_PRODUCT_REFLECTION_SURFACES)
        return n;
    if (st->has_world)
        n += sb_surfaces_level_kernels(st->level, true, out);
    out[n++] = sb_reflection_capture_kernel();
    out[n++] = sb_reflection_prefilter_kernel();
    return n;
}

const struct sb_family_baker sb_reflections_family = {
    .depends_on = reflection_depends_on,
    .key = reflection_key,
    .create = reflection_create,
    .destroy = reflection_destroy,
    .bake = reflection_bake,
    .kernels = reflection_kernels,
};
