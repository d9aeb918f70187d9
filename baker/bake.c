#include "bake.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "accuracy.h"
#include "atmosphere.h"
#include "bench.h"
#include "clouds.h"
#include "log.h"
#include "skybake_version.h"

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
    /* Dependencies point to lower ids, so one pass from the top closes the
     * set. The cloud noise reads nothing. */
    for (int p = SB_ATMOSPHERE_PRODUCT_COUNT - 1; p >= 0; p--)
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

/* Append printf-style text to a key's text at *n (of `size`). */
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static void
key_add(char *text, size_t size, size_t *n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (*n < size) {
        int w = vsnprintf(text + *n, size - *n, fmt, ap);
        *n += w > 0 ? (size_t)w : 0;
    }
    va_end(ap);
}

static void key_add3(char *text, size_t size, size_t *n, const char *name, const double v[3])
{
    key_add(text, size, n, " %s=%a,%a,%a", name, v[0], v[1], v[2]);
}

/* The parameters a product's kernels read: the medium for all; the ground's
 * albedo and the sun's irradiance for the scattering products; Mie's g for
 * those whose phase functions are not isotropic (multiscattering's is). */
static void key_params(enum sb_product_id id, const struct sb_atmosphere_params *p, char *text, size_t size, size_t *n)
{
    key_add(text, size, n, " ground_radius_km=%a top_radius_km=%a rayleigh_scale_height_km=%a mie_scale_height_km=%a",
            p->ground_radius_km, p->top_radius_km, p->rayleigh_scale_height_km, p->mie_scale_height_km);
    key_add3(text, size, n, "rayleigh_scattering_per_km", p->rayleigh_scattering_per_km);
    key_add3(text, size, n, "mie_scattering_per_km", p->mie_scattering_per_km);
    key_add3(text, size, n, "mie_absorption_per_km", p->mie_absorption_per_km);
    key_add3(text, size, n, "ozone_absorption_per_km", p->ozone_absorption_per_km);
    key_add(text, size, n, " ozone_center_km=%a ozone_half_width_km=%a", p->ozone_center_km, p->ozone_half_width_km);
    if (id == SB_PRODUCT_TRANSMITTANCE)
        return;
    key_add3(text, size, n, "ground_albedo", p->ground_albedo);
    key_add3(text, size, n, "solar_irradiance", p->solar_irradiance);
    if (id != SB_PRODUCT_MULTISCATTERING)
        key_add(text, size, n, " mie_g=%a", p->mie_g);
}

/* A cloud product's recipe, every field of its push constants, and its kernel. */
static void key_cloud(enum sb_product_id id, const struct sb_cloud_params *params, char *text, size_t size, size_t *n)
{
    struct sb_noise_push pc;
    sb_cloud_recipe(id, params, &pc);
    key_add(text, size, n, " size=%u,%u,%u inv=%a,%a,%a slice_z=%a", pc.size_x, pc.size_y, pc.size_z, (double)pc.inv_x,
            (double)pc.inv_y, (double)pc.inv_z, (double)pc.slice_z);
    for (uint32_t c = 0; c < pc.channel_count; c++)
        key_add(text, size, n, " channel%u=%u,%u,%u,%u,%u", c, pc.kind[c], pc.a[c], pc.b[c], pc.c[c], pc.seed[c]);
    char code[SB_HASH_HEX_SIZE];
    sb_cloud_code_hash(code);
    key_add(text, size, n, " code %s", code);
}

void sb_bake_keys(const struct sb_scene *scene, uint32_t mask, char out[SB_PRODUCT_COUNT][SB_HASH_HEX_SIZE])
{
    char text[8192], settings[1024], code[SB_HASH_HEX_SIZE];
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        out[p][0] = '\0';
        if (!(mask & (1u << p)))
            continue;
        enum sb_product_id id = (enum sb_product_id)p;
        size_t n = 0;
        key_add(text, sizeof(text), &n, "skybake-bake-key-v1 format %d skybake %s product %s stored %s",
                SB_PACK_FORMAT_VERSION, SKYBAKE_VERSION, sb_product_name(id), sb_product_format(id)->pixel_type);
        if (sb_product_is_cloud(id)) {
            key_cloud(id, &scene->clouds, text, sizeof(text), &n);
            sb_hash_bytes(text, n < sizeof(text) ? n : sizeof(text) - 1, out[p]);
            continue;
        }
        key_params(id, &scene->atmosphere, text, sizeof(text), &n);
        if (scene->tolerance[p] > 0) {
            key_add(text, sizeof(text), &n, " tolerance=%a candidates", scene->tolerance[p]);
            int count;
            const struct sb_atmosphere_settings *candidates = sb_bench_candidates(id, &count);
            for (int i = 0; i < count; i++) {
                sb_atmosphere_settings_json(id, &candidates[i], settings, sizeof(settings));
                key_add(text, sizeof(text), &n, " %s", settings);
            }
        } else {
            sb_atmosphere_settings_json(id, &sb_atmosphere_product(id)->defaults, settings, sizeof(settings));
            key_add(text, sizeof(text), &n, " defaults %s", settings);
        }
        sb_atmosphere_code_hash(id, code);
        key_add(text, sizeof(text), &n, " code %s", code);
        /* Dependencies point to lower ids: their keys are ready. */
        uint32_t inputs = sb_atmosphere_product(id)->depends_on;
        for (int d = 0; d < p; d++)
            if (inputs & (1u << d))
                key_add(text, sizeof(text), &n, " input %s=%s", sb_product_name((enum sb_product_id)d), out[d]);
        sb_hash_bytes(text, n < sizeof(text) ? n : sizeof(text) - 1, out[p]);
    }
}

/* The first problem an old pack's reading logged: why it is not reused. */
static void first_message(void *user, enum sb_log_level level, const char *message)
{
    char *first = user;
    if (level <= SB_LOG_WARN && !first[0])
        snprintf(first, 512, "%s", message);
}

/*
 * The pack at out_dir, when its artifacts may be reused: it verifies and was
 * baked on this device. Returns false (with *old empty) otherwise, saying
 * why unless out_dir holds no pack at all.
 */
static bool open_previous(struct sb_vk *vk, const char *out_dir, struct sb_pack *old)
{
    char manifest[4200];
    snprintf(manifest, sizeof(manifest), "%s/%s", out_dir, SB_PACK_MANIFEST);
    memset(old, 0, sizeof(*old));
    if (access(manifest, F_OK) != 0)
        return false;
    char first[512] = "";
    sb_log_set_sink(first_message, first);
    enum sb_result res = sb_pack_open(out_dir, old);
    sb_log_set_sink(NULL, NULL);
    if (res) {
        sb_warn("%s: not reusing any artifact: the pack there does not verify (%s)", out_dir, first);
        return false;
    }
    struct sb_device_info device;
    sb_vk_device_info(vk, &device);
    if (strcmp(device.name, old->device.name) || strcmp(device.driver, old->device.driver) ||
        device.vendor_id != old->device.vendor_id || device.device_id != old->device.device_id) {
        sb_info("%s: not reusing any artifact: the pack there was baked on %s (%s)", out_dir, old->device.name,
                old->device.driver);
        sb_pack_close(old);
        return false;
    }
    return true;
}

/* Bake one cloud product into *image, rounded as its file stores it. */
static enum sb_result bake_cloud(struct sb_vk *vk, const struct sb_scene *scene, enum sb_product_id id,
                                 struct sb_image *image, struct sb_artifact *a)
{
    enum sb_result res = sb_cloud_bake(vk, id, &scene->clouds, image, &a->gpu_ms);
    if (res)
        return res;
    struct sb_noise_push pc;
    sb_cloud_recipe(id, &scene->clouds, &pc);
    sb_cloud_recipe_json(&pc, a->settings_json, sizeof(a->settings_json));
    /* The noise lies in [0, 1]: binary16 cannot overflow. */
    if (sb_product_format(id)->storage == SB_STORAGE_VDB_HALF)
        res = sb_image_round_to_half(image, NULL);
    return res;
}

static void report_add(struct sb_bake_report *report, const struct sb_artifact *a, const struct sb_image *image,
                       bool reused)
{
    int i = report->artifact_count++;
    report->artifacts[i] = *a;
    report->reused[i] = reused;
    report->shapes[i][0] = image->width;
    report->shapes[i][1] = image->height;
    report->shapes[i][2] = image->depth;
    report->shapes[i][3] = image->channel_count;
    char size[48];
    if (image->depth > 1)
        snprintf(size, sizeof(size), "%ux%ux%u", image->width, image->height, image->depth);
    else
        snprintf(size, sizeof(size), "%ux%u", image->width, image->height);
    if (reused)
        sb_info("%-18s %11s x%u  reused (key unchanged)                  %s", sb_product_name(a->product), size,
                image->channel_count, a->content_hash);
    else
        sb_info("%-18s %11s x%u  gpu %9.3f ms  bake %9.3f ms  %s", sb_product_name(a->product), size,
                image->channel_count, a->gpu_ms, a->bake_ms, a->content_hash);
}

enum sb_result sb_bake_scene(struct sb_vk *vk, const struct sb_scene *scene, const char *out_dir,
                             const struct sb_bake_options *options, struct sb_bake_report *report)
{
    struct sb_pack_writer *writer = NULL;
    struct sb_atmosphere_baker *baker = NULL;
    struct sb_image baked[SB_PRODUCT_COUNT] = {0};
    char *scene_json = NULL;
    memset(report, 0, sizeof(*report));
    struct sb_pack *old = calloc(1, sizeof(*old));
    if (!old)
        return SB_ERR_NOMEM;
    bool reuse = !(options && options->force) && open_previous(vk, out_dir, old);

    uint32_t mask = sb_bake_closure(scene);
    enum sb_result res = sb_pack_writer_create(out_dir, &writer);
    if (res)
        goto cleanup;
    if ((mask & ((1u << SB_ATMOSPHERE_PRODUCT_COUNT) - 1)) &&
        (res = sb_atmosphere_baker_create(vk, &scene->atmosphere, &baker)))
        goto cleanup;

    char keys[SB_PRODUCT_COUNT][SB_HASH_HEX_SIZE];
    sb_bake_keys(scene, mask, keys);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        if (!(mask & (1u << p)))
            continue;
        enum sb_product_id id = (enum sb_product_id)p;
        const struct sb_product_format *format = sb_product_format(id);
        struct sb_artifact artifact = {.product = id}, *a = &artifact;
        snprintf(a->file, sizeof(a->file), "%s.%s", format->name, format->extension);
        snprintf(a->parameterization, sizeof(a->parameterization), "%s", format->parameterization);
        memcpy(a->key, keys[p], SB_HASH_HEX_SIZE);

        if (reuse && old->present[p] && !strcmp(old->artifacts[p].key, keys[p])) {
            /* Verified when the old pack was opened; the writer hashes it again. */
            const struct sb_artifact *was = &old->artifacts[p];
            snprintf(a->settings_json, sizeof(a->settings_json), "%s", was->settings_json);
            a->bake_ms = was->bake_ms;
            a->gpu_ms = was->gpu_ms;
            baked[p] = old->images[p];
            old->images[p] = (struct sb_image){0};
            if ((!sb_product_is_cloud(id) && (res = sb_atmosphere_adopt(baker, id, &baked[p]))) ||
                (res = sb_pack_writer_add_image(writer, a, &baked[p])))
                goto cleanup;
            if (strcmp(a->content_hash, was->content_hash) != 0) {
                sb_error("%s: %s: content hash %s on writing, %s when read", out_dir, sb_product_name(id),
                         a->content_hash, was->content_hash);
                res = SB_ERR_HASH_MISMATCH;
                goto cleanup;
            }
            report_add(report, a, &baked[p], true);
            continue;
        }

        double t0 = now_ms();
        struct sb_image *image = &baked[p];
        if (sb_product_is_cloud(id)) {
            if ((res = bake_cloud(vk, scene, id, image, a)))
                goto cleanup;
            a->bake_ms = now_ms() - t0;
        } else {
            struct sb_atmosphere_settings used;
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
        }
        if ((res = sb_pack_writer_add_image(writer, a, image)))
            goto cleanup;
        report_add(report, a, image, false);
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
    sb_pack_close(old);
    free(old);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        sb_image_finish(&baked[p]);
    sb_atmosphere_baker_destroy(&baker);
    sb_pack_writer_destroy(&writer);
    return res;
}
