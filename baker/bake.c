#include "bake.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "accuracy.h"
#include "atmosphere.h"
#include "bench.h"
#include "log.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

uint32_t sb_bake_closure(const struct sb_scene *scene)
{
    uint32_t mask = 0;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        if (scene->wants[p])
            mask |= 1u << p;
    /* Dependencies point to lower ids, so one pass from the top closes the set. */
    for (int p = SB_PRODUCT_COUNT - 1; p >= 0; p--)
        if (mask & (1u << p))
            mask |= sb_atmosphere_product((enum sb_product_id)p)->depends_on;
    return mask;
}

/*
 * Bake product `id` with the cheapest setting (device-independent cost,
 * sb_atmosphere_settings_cost) whose max relative error against the fp64
 * reference, at the probe points accuracy.h names, is within `tolerance`.
 * Candidates are baked cheapest first until one is; *image holds it and the
 * baker keeps it for the products that read it.
 */
static enum sb_result bake_to_tolerance(struct sb_atmosphere_baker *baker, const struct sb_atmosphere_params *params,
                                        enum sb_product_id id, double tolerance,
                                        const struct sb_image baked[SB_PRODUCT_COUNT], struct sb_image *image,
                                        struct sb_atmosphere_settings *used, struct sb_error *error, char *probe,
                                        size_t probe_size, double *gpu_ms)
{
    const char *name = sb_product_name(id);
    struct sb_accuracy_ref *ref = NULL;
    enum sb_result res = sb_accuracy_ref_create(params, id, false, 0, 0, baked, &ref);
    if (res)
        return res;
    snprintf(probe, probe_size, "%s", sb_accuracy_ref_probe(ref));
    int count;
    const struct sb_atmosphere_settings *candidates = sb_bench_candidates(id, &count);
    double best = INFINITY;
    char best_label[48] = "", label[48];
    double total_ms = 0;
    res = SB_ERR_TOLERANCE;
    for (int i = 0; i < count; i++) {
        double ms = 0;
        sb_image_finish(image);
        enum sb_result r = sb_atmosphere_bake(baker, id, &candidates[i], image, used, &ms);
        if (r) {
            res = r;
            break;
        }
        total_ms += ms;
        sb_accuracy_measure(ref, image, false, error);
        sb_atmosphere_settings_label(id, used, label, sizeof(label));
        sb_debug("%s: %s: max rel error %.3g (tolerance %g)", name, label, error->max_rel, tolerance);
        if (error->max_rel < best) {
            best = error->max_rel;
            snprintf(best_label, sizeof(best_label), "%s", label);
        }
        if (error->max_rel <= tolerance) {
            sb_info("%s: %s is the cheapest setting within tolerance %g (max rel error %.3g at %s)", name, label,
                    tolerance, error->max_rel, probe);
            res = SB_OK;
            break;
        }
    }
    if (res == SB_ERR_TOLERANCE)
        sb_error("%s: no setting reaches tolerance %g; the best reachable is %.3g (%s), at %s", name, tolerance, best,
                 best_label, probe);
    if (res)
        sb_image_finish(image);
    *gpu_ms = total_ms;
    sb_accuracy_ref_destroy(&ref);
    return res;
}

/* The settings' JSON object with the tolerance and the measured error added. */
static void add_error_json(char *json, size_t size, double tolerance, const struct sb_error *e, const char *probe)
{
    size_t len = strlen(json);
    if (!len || json[len - 1] != '}')
        return;
    snprintf(json + len - 1, size - (len - 1),
             ",\"tolerance\":%.17g,\"error\":{\"max_rel\":%.6g,\"rms_rel\":%.6g,\"values\":%u,"
             "\"against\":\"fp64 reference\",\"at\":\"%s\"}}",
             tolerance, e->max_rel, e->rms_rel, e->count, probe);
}

enum sb_result sb_bake_scene(struct sb_vk *vk, const struct sb_scene *scene, const char *out_dir,
                             struct sb_bake_report *report)
{
    struct sb_pack_writer *writer = NULL;
    struct sb_atmosphere_baker *baker = NULL;
    struct sb_image baked[SB_PRODUCT_COUNT] = {0};
    char *scene_json = NULL;
    memset(report, 0, sizeof(*report));

    enum sb_result res = sb_pack_writer_create(out_dir, &writer);
    if (res)
        goto cleanup;
    if ((res = sb_atmosphere_baker_create(vk, &scene->atmosphere, &baker)))
        goto cleanup;

    uint32_t mask = sb_bake_closure(scene);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        if (!(mask & (1u << p)))
            continue;
        enum sb_product_id id = (enum sb_product_id)p;
        struct sb_artifact *a = &report->artifacts[report->artifact_count];
        struct sb_atmosphere_settings used;
        memset(a, 0, sizeof(*a));
        a->product = id;
        snprintf(a->file, sizeof(a->file), "%s.exr", sb_product_name(id));
        snprintf(a->parameterization, sizeof(a->parameterization), "%s", sb_product_format(id)->parameterization);

        double t0 = now_ms();
        struct sb_image *image = &baked[p];
        struct sb_error error;
        char probe[96];
        double tolerance = scene->tolerance[p];
        if (tolerance > 0)
            res = bake_to_tolerance(baker, &scene->atmosphere, id, tolerance, baked, image, &used, &error, probe,
                                    sizeof(probe), &a->gpu_ms);
        else
            res = sb_atmosphere_bake(baker, id, NULL, image, &used, &a->gpu_ms);
        if (res)
            goto cleanup;
        a->bake_ms = now_ms() - t0;
        sb_atmosphere_settings_json(id, &used, a->settings_json, sizeof(a->settings_json));
        if (tolerance > 0)
            add_error_json(a->settings_json, sizeof(a->settings_json), tolerance, &error, probe);
        if ((res = sb_pack_writer_add_image(writer, a, image)))
            goto cleanup;
        report->shapes[report->artifact_count][0] = image->width;
        report->shapes[report->artifact_count][1] = image->height;
        report->shapes[report->artifact_count][2] = image->channel_count;
        report->artifact_count++;
        sb_info("%-18s %4ux%-3u x%u  gpu %9.3f ms  bake %9.3f ms  %s", sb_product_name(id), image->width, image->height,
                image->channel_count, a->gpu_ms, a->bake_ms, a->content_hash);
    }

    scene_json = sb_scene_normalized_json(scene);
    if (!scene_json) {
        res = SB_ERR_NOMEM;
        goto cleanup;
    }
    struct sb_device_info device;
    sb_vk_device_info(vk, &device);
    res = sb_pack_writer_commit(&writer, scene_json, &device);

cleanup:
    free(scene_json);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        sb_image_finish(&baked[p]);
    sb_atmosphere_baker_destroy(&baker);
    sb_pack_writer_destroy(&writer);
    return res;
}
