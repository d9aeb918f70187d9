#include "bake.h"

#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "family.h"
#include "log.h"
#include "parallel.h"
#include "pipeline.h"
#include "skybake_version.h"

static uint32_t depends_on(enum sb_product_id id)
{
    const struct sb_family_baker *family = sb_product_baker(id);
    uint32_t inputs = family->depends_on ? family->depends_on(id) : 0;
    assert(inputs < 1u << id); /* lower ids only */
    return inputs;
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
            mask |= depends_on((enum sb_product_id)p);
    return mask;
}

void sb_bake_keys(const struct sb_scene *scene, uint32_t mask, void *const states[SB_FAMILY_COUNT],
                  char out[SB_PRODUCT_COUNT][SB_HASH_HEX_SIZE])
{
    struct sb_key_text key;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        out[p][0] = '\0';
        if (!(mask & (1u << p)))
            continue;
        enum sb_product_id id = (enum sb_product_id)p;
        key.length = 0;
        sb_key_add(&key, "skybake-bake-key-v1 format %d skybake %s product %s stored %s", SB_PACK_FORMAT_VERSION,
                   SKYBAKE_VERSION, sb_product_name(id), sb_product_format(id)->pixel_type);
        sb_product_baker(id)->key(states[sb_product_format(id)->family], scene, id, &key);
        /* Dependencies point to lower ids: their keys are ready. */
        uint32_t inputs = depends_on(id);
        for (int d = 0; d < p; d++)
            if (inputs & (1u << d))
                sb_key_add(&key, " input %s=%s", sb_product_name((enum sb_product_id)d), out[d]);
        sb_hash_bytes(key.text, key.length < sizeof(key.text) ? key.length : sizeof(key.text) - 1, out[p]);
    }
}

/* Whether product `id` of the previous pack `old` (NULL: none) is reused. */
static bool reusable(const struct sb_pack *old, enum sb_product_id id, const char *key)
{
    return old && old->present[id] && !strcmp(old->artifacts[id].key, key);
}

/* Every kernel the products to bake make, compiled at once on every core. */
static void prepare_kernels(struct sb_vk *vk, const struct sb_scene *scene, uint32_t mask, const struct sb_pack *old,
                            const char keys[SB_PRODUCT_COUNT][SB_HASH_HEX_SIZE], void *states[SB_FAMILY_COUNT])
{
    struct sb_pipeline_params params[SB_PRODUCT_COUNT * SB_FAMILY_KERNELS_MAX];
    uint32_t count = 0;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        enum sb_product_id id = (enum sb_product_id)p;
        enum sb_family f = sb_product_format(id)->family;
        const struct sb_family_baker *family = sb_family_baker(f);
        if ((mask & (1u << p)) && family->kernels && !reusable(old, id, keys[p]))
            count += family->kernels(states[f], scene, id, &params[count]);
    }
    if (count) {
        sb_status("compiling %u kernels", count);
        sb_pipelines_prepare(vk, params, count, sb_parallel_threads());
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
    void *states[SB_FAMILY_COUNT] = {0};
    struct sb_image baked[SB_PRODUCT_COUNT] = {0};
    char *scene_json = NULL;
    memset(report, 0, sizeof(*report));
    struct sb_pack *old = calloc(1, sizeof(*old));
    if (!old)
        return SB_ERR_NOMEM;
    double opened = sb_now_s();
    bool reuse = !(options && options->force) && open_previous(vk, out_dir, old);
    if (reuse)
        sb_debug("bake: the pack there read and verified in %.1f ms", 1e3 * (sb_now_s() - opened));
    /* --from packs: verified and of this device, else left out (saying why) */
    struct sb_pack *from[SB_BAKE_MAX_FROM] = {0};
    int from_count = 0;
    for (int k = 0; options && !options->force && k < options->from_count && k < SB_BAKE_MAX_FROM; k++) {
        struct sb_pack *pack = calloc(1, sizeof(*pack));
        if (!pack)
            break;
        if (open_previous(vk, options->from[k], pack)) {
            from[from_count++] = pack;
            continue;
        }
        char manifest[4200];
        snprintf(manifest, sizeof(manifest), "%s/%s", options->from[k], SB_PACK_MANIFEST);
        if (access(manifest, F_OK) != 0)
            sb_warn("%s (--from): no pack there", options->from[k]);
        free(pack);
    }

    uint32_t mask = sb_bake_closure(scene);
    enum sb_result res = sb_pack_writer_create(out_dir, &writer);
    if (res)
        goto cleanup;
    double created = sb_now_s();
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        enum sb_family f = sb_product_format((enum sb_product_id)p)->family;
        const struct sb_family_baker *family = sb_family_baker(f);
        if ((mask & (1u << p)) && family->create && !states[f] && (res = family->create(vk, scene, &states[f])))
            goto cleanup;
    }
    double keyed = sb_now_s();
    char keys[SB_PRODUCT_COUNT][SB_HASH_HEX_SIZE];
    sb_bake_keys(scene, mask, states, keys);
    prepare_kernels(vk, scene, mask, reuse ? old : NULL, keys, states);
    sb_debug("bake: the families ready (worlds read) in %.1f ms, keys and kernels in %.1f ms", 1e3 * (keyed - created),
             1e3 * (sb_now_s() - keyed));
    int total = 0, done = 0;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        total += (mask >> p) & 1;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        if (!(mask & (1u << p)))
            continue;
        sb_status("%s (%d of %d products)", sb_product_name((enum sb_product_id)p), ++done, total);
        enum sb_product_id id = (enum sb_product_id)p;
        const struct sb_product_format *format = sb_product_format(id);
        const struct sb_family_baker *family = sb_family_baker(format->family);
        void *state = states[format->family];
        struct sb_artifact artifact = {.product = id}, *a = &artifact;
        snprintf(a->file, sizeof(a->file), "%s.%s", format->name, format->extension);
        snprintf(a->parameterization, sizeof(a->parameterization), "%s", format->parameterization);
        memcpy(a->key, keys[p], SB_HASH_HEX_SIZE);

        if (reuse && reusable(old, id, keys[p])) {
            /* Verified when the old pack was opened; the writer hashes it again. */
            const struct sb_artifact *was = &old->artifacts[p];
            snprintf(a->settings_json, sizeof(a->settings_json), "%s", was->settings_json);
            a->bake_ms = was->bake_ms;
            a->gpu_ms = was->gpu_ms;
            memcpy(a->world_hash, was->world_hash, sizeof(a->world_hash)); /* the world it was baked against */
            memcpy(a->world_path, was->world_path, sizeof(a->world_path));
            a->probes = was->probes; /* its columns and sight masks move with it */
            old->artifacts[p].probes.columns = NULL;
            old->artifacts[p].probes.sight = NULL;
            old->artifacts[p].probes.tiles = NULL;
            old->artifacts[p].probes.column_count = 0;
            old->artifacts[p].probes.tile_count = 0;
            baked[p] = old->images[p];
            old->images[p] = (struct sb_image){0};
            if ((family->adopt && (res = family->adopt(state, id, &baked[p]))) ||
                (res = sb_pack_writer_add_image(writer, a, &baked[p]))) {
                sb_probe_layout_finish(&a->probes);
                goto cleanup;
            }
            sb_probe_layout_finish(&a->probes);
            if (strcmp(a->content_hash, was->content_hash) != 0) {
                sb_error("%s: %s: content hash %s on writing, %s when read", out_dir, sb_product_name(id),
                         a->content_hash, was->content_hash);
                res = SB_ERR_HASH_MISMATCH;
                goto cleanup;
            }
            report_add(report, a, &baked[p], true);
            continue;
        }

        if (reuse && old->present[id] && family->previous)
            family->previous(state, id, &old->artifacts[p], &old->images[p]);
        for (int k = 0; k < from_count && family->previous; k++)
            if (from[k]->present[id])
                family->previous(state, id, &from[k]->artifacts[p], &from[k]->images[p]);
        double t0 = 1e3 * sb_now_s();
        struct sb_image *image = &baked[p];
        if ((res = family->bake(state, vk, scene, id, baked, image, a))) {
            sb_probe_layout_finish(&a->probes);
            goto cleanup;
        }
        a->bake_ms = 1e3 * sb_now_s() - t0;
        if (!image->data) { /* declined under the scene's tolerance (family.h): not in the pack */
            report->declined |= 1u << p;
            sb_probe_layout_finish(&a->probes);
            continue;
        }
        double added = sb_now_s();
        res = sb_pack_writer_add_image(writer, a, image);
        sb_debug("%s: written and hashed in %.1f ms", sb_product_name(id), 1e3 * (sb_now_s() - added));
        sb_probe_layout_finish(&a->probes);
        if (res)
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
    sb_status("writing the pack");
    double written = sb_now_s();
    res = sb_pack_writer_commit(&writer, scene_json, &device);
    sb_debug("bake: the pack committed in %.1f ms", 1e3 * (sb_now_s() - written));

cleanup:
    sb_status(NULL);
    if (sb_compute_pipelines_unused(vk))
        sb_debug("pipelines: %u kernels compiled ahead were not used", sb_compute_pipelines_unused(vk));
    free(scene_json);
    sb_pack_close(old);
    free(old);
    for (int k = 0; k < from_count; k++) {
        sb_pack_close(from[k]);
        free(from[k]);
    }
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        sb_image_finish(&baked[p]);
    for (int f = 0; f < SB_FAMILY_COUNT; f++)
        if (states[f])
            sb_family_baker((enum sb_family)f)->destroy(&states[f]);
    sb_pack_writer_destroy(&writer);
    return res;
}
