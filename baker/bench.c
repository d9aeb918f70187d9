#include "bench.h"

#include "clouds.h"

#include <cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "json.h"
#include "log.h"

/* The sweeps are the products' candidate settings (atmosphere_candidates.c). */
_Static_assert((int)SB_BENCH_SWEEP_COUNT == (int)SB_ATMOSPHERE_SWEEP_COUNT, "bench.h's sweeps are atmosphere.h's");
bool sb_bench_sweep_from_name(const char *name, enum sb_bench_sweep *sweep)
{
    for (int i = 0; i < SB_BENCH_SWEEP_COUNT; i++)
        if (!strcmp(name, sb_atmosphere_sweeps[i].name)) {
            *sweep = (enum sb_bench_sweep)i;
            return true;
        }
    return false;
}

static bool same_settings(enum sb_product_id id, const struct sb_atmosphere_settings *a,
                          const struct sb_atmosphere_settings *b)
{
    char la[48], lb[48];
    sb_atmosphere_settings_label(id, a, la, sizeof(la));
    sb_atmosphere_settings_label(id, b, lb, sizeof(lb));
    return !strcmp(la, lb);
}

/* Whether row a dominates row b of the same sweep: at most b's time and
 * error, and less of one of them. */
static bool dominates(const struct sb_bench_row *a, const struct sb_bench_row *b)
{
    return a->sweep == b->sweep && isfinite(a->error.max_rel) && a->gpu_ms <= b->gpu_ms &&
           a->error.max_rel <= b->error.max_rel && (a->gpu_ms < b->gpu_ms || a->error.max_rel < b->error.max_rel);
}

/* Rows on the Pareto front of their sweep: no other row is as fast or faster
 * and strictly more accurate, or strictly faster and as accurate. */
static void mark_pareto(struct sb_bench_row *rows, int count)
{
    for (int i = 0; i < count; i++) {
        rows[i].pareto = isfinite(rows[i].error.max_rel);
        for (int j = 0; j < count && rows[i].pareto; j++)
            if (j != i && dominates(&rows[j], &rows[i]))
                rows[i].pareto = false;
    }
}

/* Each anchor row against skybake's settings of its sweep (not the other
 * published rows, nor their variants). */
static void mark_anchors(struct sb_bench_row *rows, int count)
{
    for (int i = 0; i < count; i++) {
        rows[i].dominated_by = -1;
        rows[i].dominated_by_default = false;
        if (!rows[i].anchor)
            continue;
        for (int j = 0; j < count; j++) {
            if (!rows[j].ours || !dominates(&rows[j], &rows[i]))
                continue;
            if (rows[i].dominated_by < 0 || rows[j].gpu_ms < rows[rows[i].dominated_by].gpu_ms)
                rows[i].dominated_by = j;
            rows[i].dominated_by_default = rows[i].dominated_by_default || rows[j].is_default;
        }
    }
}

/* The cloud noise: GPU bakes (median of the repeats) against the reference
 * on this thread, every texel compared. */
static enum sb_result bench_clouds(struct sb_vk *vk, const struct sb_bench_params *params, int repeat, double *times,
                                   struct sb_bench_report *report)
{
    enum sb_result res = SB_OK;
    for (int p = 0; p < SB_PRODUCT_COUNT && !res; p++) {
        if (!params->clouds[p])
            continue;
        enum sb_product_id id = (enum sb_product_id)p;
        struct sb_bench_cloud_row *row = &report->cloud_rows[report->cloud_row_count++];
        row->product = id;
        struct sb_image image = {0};
        /* one untimed bake first when timing repeats, as for the atmosphere */
        for (int k = repeat >= 3 ? -1 : 0; k < repeat && !res; k++) {
            double ms;
            sb_image_finish(&image);
            res = sb_warm_up(vk, k <= 0 ? SB_WARM_UP_MS : SB_KEEP_WARM_MS);
            if (!res)
                res = sb_cloud_bake(vk, id, &params->cloud_params, &image, k >= 0 ? &times[k] : &ms);
        }
        if (res)
            break;
        row->gpu_ms = sb_bench_median(times, repeat); /* sorts them */
        row->gpu_ms_min = times[0];
        row->shape[0] = image.width;
        row->shape[1] = image.height;
        row->shape[2] = image.depth;
        row->channel_count = image.channel_count;
        struct sb_noise_push pc;
        sb_cloud_recipe(id, &params->cloud_params, &pc);
        float *ref = malloc(sb_image_float_count(&image) * sizeof(float));
        if (!ref) {
            sb_image_finish(&image);
            res = SB_ERR_NOMEM;
            break;
        }
        double t0 = sb_now_s();
        sb_cloud_ref(&pc, 0, (uint64_t)image.width * image.height * image.depth, ref);
        row->reference_ms = (sb_now_s() - t0) * 1e3;
        row->values = sb_image_float_count(&image);
        for (uint64_t i = 0; i < row->values; i++)
            row->differing += memcmp(&ref[i], &image.data[i], sizeof(float)) != 0;
        free(ref);
        sb_image_finish(&image);
        sb_info("%s: gpu %.3f ms, reference %.0f ms, %llu of %llu values differ", sb_product_name(id), row->gpu_ms,
                row->reference_ms, (unsigned long long)row->differing, (unsigned long long)row->values);
    }
    return res;
}

enum sb_result sb_bench_run(struct sb_vk *vk, const struct sb_atmosphere_params *atmosphere,
                            const struct sb_bench_params *params, struct sb_bench_report *report)
{
    memset(report, 0, sizeof(*report));
    struct sb_atmosphere_baker *baker = NULL;
    struct sb_image inputs[SB_PRODUCT_COUNT] = {0}, image = {0};
    struct sb_accuracy_ref *ref = NULL;
    int repeat = params->repeat > 0 ? params->repeat : 1;
    double *times = calloc((size_t)repeat, sizeof(double));
    int total = 0;
    for (int w = 0; w < SB_BENCH_SWEEP_COUNT; w++)
        total += params->sweeps[w] ? sb_atmosphere_sweeps[w].count : 0;
    report->rows = calloc((size_t)total + 1, sizeof(*report->rows));
    enum sb_result res = times && report->rows ? SB_OK : SB_ERR_NOMEM;
    if (!res)
        res = sb_atmosphere_baker_create(vk, atmosphere, &baker);

    /* Every product a sweep reads, and the product itself, baked at its
     * defaults first: the sweeps of later products read these. */
    uint32_t need = 0;
    for (int w = 0; w < SB_BENCH_SWEEP_COUNT; w++)
        if (params->sweeps[w])
            need |= sb_atmosphere_product(sb_atmosphere_sweeps[w].product)->depends_on |
                    1u << sb_atmosphere_sweeps[w].product;
    for (int p = 0; p < SB_ATMOSPHERE_PRODUCT_COUNT && !res; p++)
        if (need & 1u << p)
            res = sb_atmosphere_bake(baker, (enum sb_product_id)p, NULL, &inputs[p], NULL, NULL);

    for (int w = 0; w < SB_BENCH_SWEEP_COUNT && !res; w++) {
        if (!params->sweeps[w])
            continue;
        enum sb_product_id id = sb_atmosphere_sweeps[w].product;
        const struct sb_atmosphere_product *product = sb_atmosphere_product(id);
        double t0 = sb_now_s();
        if ((res = sb_accuracy_ref_create(atmosphere, id, sb_atmosphere_sweeps[w].lookup ? SB_ACCURACY_LOOKUP : 0, 0, 0,
                                          inputs, &ref)))
            break;
        report->reference_s[w] = sb_now_s() - t0;
        snprintf(report->probe[w], sizeof(report->probe[w]), "%s", sb_accuracy_ref_probe(ref));
        sb_info("%s: fp64 reference at %s in %.1f s", sb_atmosphere_sweeps[w].name, report->probe[w],
                report->reference_s[w]);

        for (int e = 0; e < sb_atmosphere_sweeps[w].count && !res; e++) {
            const struct sb_atmosphere_candidate *entry = &sb_atmosphere_sweeps[w].entries[e];
            if (params->quick && !entry->quick)
                continue;
            struct sb_bench_row *row = &report->rows[report->row_count];
            row->sweep = (enum sb_bench_sweep)w;
            row->anchor = entry->anchor;
            row->ours = entry->settings.quadrature == SB_QUADRATURE_GAUSS_LEGENDRE;
            row->cost = sb_atmosphere_settings_cost(id, &entry->settings);
            sb_atmosphere_settings_label(id, &entry->settings, row->label, sizeof(row->label));
            /* one untimed bake first when timing repeats: pipeline caches settle */
            for (int k = repeat >= 3 ? -1 : 0; k < repeat && !res; k++) {
                double ms;
                sb_image_finish(&image);
                res = sb_warm_up(vk, k <= 0 ? SB_WARM_UP_MS : SB_KEEP_WARM_MS);
                if (!res)
                    res = sb_atmosphere_bake(baker, id, &entry->settings, &image, &row->settings,
                                             k >= 0 ? &times[k] : &ms);
            }
            if (res)
                break;
            const struct sb_product_format *format = sb_product_format(id);
            struct sb_atmosphere_settings at_format = row->settings;
            if (at_format.width == format->width && at_format.height == format->height)
                at_format.width = at_format.height = 0;
            row->is_default = same_settings(id, &at_format, &product->defaults);
            row->gpu_ms = sb_bench_median(times, repeat); /* sorts them */
            row->gpu_ms_min = times[0];
            sb_accuracy_measure(ref, &image, false, &row->error);
            sb_accuracy_measure(ref, &image, true, &row->error_half);
            report->row_count++;
            sb_info("%-24s %-22s %10.3f ms  max %.3g  rms %.3g", sb_atmosphere_sweeps[w].name, row->label, row->gpu_ms,
                    row->error.max_rel, row->error.rms_rel);
        }
        sb_accuracy_ref_destroy(&ref);
        /* Later sweeps read this product at its defaults again. */
        sb_image_finish(&image);
        if (!res)
            res = sb_atmosphere_bake(baker, id, NULL, &image, NULL, NULL);
    }
    if (!res)
        res = bench_clouds(vk, params, repeat, times, report);
    if (!res && params->probes)
        res = sb_bench_probes(vk, params, report);
    if (!res && params->reflection)
        res = sb_bench_reflection(vk, atmosphere, params, report);
    if (!res)
        mark_pareto(report->rows, report->row_count);
    if (!res)
        mark_anchors(report->rows, report->row_count);
    sb_image_finish(&image);
    for (int p = 0; p < SB_ATMOSPHERE_PRODUCT_COUNT; p++)
        sb_image_finish(&inputs[p]);
    sb_accuracy_ref_destroy(&ref);
    sb_atmosphere_baker_destroy(&baker);
    free(times);
    if (res)
        sb_bench_report_finish(report);
    return res;
}

void sb_bench_report_finish(struct sb_bench_report *report)
{
    free(report->rows);
    memset(report, 0, sizeof(*report));
}

/* ---- Output ---------------------------------------------------------------------- */

/* Sweep w's default row, or NULL where the sweep (--quick) left it out. */
static const struct sb_bench_row *default_row(const struct sb_bench_report *report, int w)
{
    for (int i = 0; i < report->row_count; i++)
        if (report->rows[i].sweep == (enum sb_bench_sweep)w && report->rows[i].is_default)
            return &report->rows[i];
    return NULL;
}

/* The most accurate row of anchor row r's own rule (r or a variant of it:
 * more directions, more steps) in its sweep, or NULL where r is that row. */
static const struct sb_bench_row *rule_best(const struct sb_bench_report *report, const struct sb_bench_row *r)
{
    const struct sb_bench_row *best = r;
    for (int i = 0; i < report->row_count; i++) {
        const struct sb_bench_row *v = &report->rows[i];
        if (v->sweep == r->sweep && !v->ours && v->settings.quadrature == r->settings.quadrature &&
            isfinite(v->error.max_rel) && v->error.max_rel < best->error.max_rel)
            best = v;
    }
    return best != r ? best : NULL;
}

/* The default's time and error as multiples of anchor row r's; false where
 * the sweep has no default row or the ratios are undefined. */
static bool default_ratios(const struct sb_bench_report *report, const struct sb_bench_row *r, double *time,
                           double *error)
{
    const struct sb_bench_row *def = default_row(report, r->sweep);
    if (!def || !(r->gpu_ms > 0) || !(r->error.max_rel > 0) || !isfinite(def->error.max_rel))
        return false;
    *time = def->gpu_ms / r->gpu_ms;
    *error = def->error.max_rel / r->error.max_rel;
    return true;
}

static cJSON *report_json(const struct sb_bench_report *report, const struct sb_vk *vk)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "device", vk->properties.deviceName);
    cJSON_AddStringToObject(root, "driver", vk->driver_name);
    cJSON *sw = cJSON_AddObjectToObject(root, "sweeps");
    for (int w = 0; w < SB_BENCH_SWEEP_COUNT; w++) {
        if (!report->probe[w][0])
            continue;
        cJSON *o = cJSON_AddObjectToObject(sw, sb_atmosphere_sweeps[w].name);
        cJSON_AddStringToObject(o, "product", sb_product_name(sb_atmosphere_sweeps[w].product));
        cJSON_AddStringToObject(o, "error", sb_atmosphere_sweeps[w].error_name);
        cJSON_AddStringToObject(o, "probe", report->probe[w]);
        cJSON_AddNumberToObject(o, "reference_s", report->reference_s[w]);
    }
    cJSON *rows = cJSON_AddArrayToObject(root, "rows");
    for (int i = 0; i < report->row_count; i++) {
        const struct sb_bench_row *r = &report->rows[i];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "sweep", sb_atmosphere_sweeps[r->sweep].name);
        cJSON_AddStringToObject(o, "setting", r->label);
        if (r->anchor)
            cJSON_AddStringToObject(o, "anchor", r->anchor);
        cJSON_AddBoolToObject(o, "default", r->is_default);
        cJSON_AddBoolToObject(o, "ours", r->ours);
        cJSON_AddNumberToObject(o, "cost", (double)r->cost);
        cJSON_AddNumberToObject(o, "gpu_ms", r->gpu_ms);
        cJSON_AddNumberToObject(o, "gpu_ms_min", r->gpu_ms_min);
        cJSON_AddNumberToObject(o, "max_rel", isfinite(r->error.max_rel) ? r->error.max_rel : -1);
        cJSON_AddNumberToObject(o, "rms_rel", isfinite(r->error.rms_rel) ? r->error.rms_rel : -1);
        cJSON_AddNumberToObject(o, "max_rel_fp16", isfinite(r->error_half.max_rel) ? r->error_half.max_rel : -1);
        cJSON_AddNumberToObject(o, "rms_rel_fp16", isfinite(r->error_half.rms_rel) ? r->error_half.rms_rel : -1);
        cJSON_AddNumberToObject(o, "values", r->error.count);
        cJSON *worst = cJSON_AddArrayToObject(o, "worst_texel");
        cJSON_AddItemToArray(worst, cJSON_CreateNumber(r->error.worst_x));
        cJSON_AddItemToArray(worst, cJSON_CreateNumber(r->error.worst_y));
        cJSON_AddItemToArray(worst, cJSON_CreateNumber(r->error.worst_channel));
        cJSON_AddBoolToObject(o, "pareto", r->pareto);
        if (r->anchor) {
            double time, error;
            if (default_ratios(report, r, &time, &error)) {
                cJSON_AddNumberToObject(o, "default_time_ratio", time);
                cJSON_AddNumberToObject(o, "default_error_ratio", error);
            }
            const struct sb_bench_row *best = rule_best(report, r);
            if (best && default_ratios(report, best, &time, &error)) {
                cJSON_AddStringToObject(o, "rule_best", best->label);
                cJSON_AddNumberToObject(o, "rule_best_default_time_ratio", time);
                cJSON_AddNumberToObject(o, "rule_best_default_error_ratio", error);
            }
            cJSON_AddBoolToObject(o, "dominated_by_default", r->dominated_by_default);
            if (r->dominated_by >= 0)
                cJSON_AddStringToObject(o, "dominated_by", report->rows[r->dominated_by].label);
            else
                cJSON_AddNullToObject(o, "dominated_by");
        }
        cJSON_AddItemToArray(rows, o);
    }
    for (int i = 0; i < report->probe_row_count; i++) {
        const struct sb_bench_probe_row *r = &report->probe_rows[i];
        cJSON *arr = cJSON_GetObjectItem(root, "sky_visibility");
        if (!arr)
            arr = cJSON_AddArrayToObject(root, "sky_visibility");
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "scene", r->scene);
        cJSON_AddNumberToObject(o, "triangles", r->triangles);
        cJSON_AddNumberToObject(o, "probes", r->probes);
        cJSON_AddNumberToObject(o, "rays_per_probe", r->rays_per_probe);
        cJSON_AddNumberToObject(o, "bvh_ms", r->bvh_ms);
        cJSON_AddNumberToObject(o, "bvh_threads", r->bvh_threads);
        cJSON_AddNumberToObject(o, "bvh_one_thread_ms", r->bvh_one_thread_ms);
        cJSON_AddNumberToObject(o, "embree_medium_build_ms", r->embree_medium_ms);
        cJSON_AddNumberToObject(o, "embree_high_build_ms", r->embree_high_ms);
        cJSON_AddNumberToObject(o, "gpu_ms", r->gpu_ms);
        cJSON_AddNumberToObject(o, "gpu_rays_per_s", r->gpu_rays_per_s);
        cJSON_AddNumberToObject(o, "embree_s", r->embree_s);
        cJSON_AddNumberToObject(o, "embree_threads", r->embree_threads);
        cJSON_AddNumberToObject(o, "embree_rays_per_s", r->embree_rays_per_s);
        cJSON_AddNumberToObject(o, "hits_differ", (double)r->hits_differ);
        cJSON_AddNumberToObject(o, "bounce_rays", r->bounce_rays);
        cJSON_AddNumberToObject(o, "bounce_secondary", r->bounce_secondary);
        cJSON_AddNumberToObject(o, "bounce_gpu_ms", r->bounce_ms);
        cJSON_AddItemToArray(arr, o);
    }
    if (report->cloud_row_count) {
        cJSON *clouds = cJSON_AddArrayToObject(root, "clouds");
        for (int i = 0; i < report->cloud_row_count; i++) {
            const struct sb_bench_cloud_row *r = &report->cloud_rows[i];
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "product", sb_product_name(r->product));
            cJSON_AddItemToObject(
                o, "shape",
                cJSON_CreateIntArray((const int[]){(int)r->shape[0], (int)r->shape[1], (int)r->shape[2]}, 3));
            cJSON_AddNumberToObject(o, "channels", r->channel_count);
            cJSON_AddNumberToObject(o, "gpu_ms", r->gpu_ms);
            cJSON_AddNumberToObject(o, "gpu_ms_min", r->gpu_ms_min);
            cJSON_AddNumberToObject(o, "reference_ms_one_core", r->reference_ms);
            cJSON_AddNumberToObject(o, "values", (double)r->values);
            cJSON_AddNumberToObject(o, "differing", (double)r->differing);
            cJSON_AddItemToArray(clouds, o);
        }
    }
    return root;
}

/* Each published row of sweep w against skybake's default and settings,
 * all measured in this run. */
static void print_anchors(const struct sb_bench_report *report, int w)
{
    const struct sb_bench_row *def = default_row(report, w);
    for (int i = 0; i < report->row_count; i++) {
        const struct sb_bench_row *r = &report->rows[i];
        if (r->sweep != (enum sb_bench_sweep)w || !r->anchor)
            continue;
        printf("  against %s:", r->label);
        double time, error;
        if (default_ratios(report, r, &time, &error))
            printf(" the default (%s) takes %.3gx its time at %.3gx its error;", def->label, time, error);
        const char *fastest = r->dominated_by >= 0 ? report->rows[r->dominated_by].label : NULL;
        if (r->dominated_by_default && &report->rows[r->dominated_by] == def)
            printf(" the default dominates it, the fastest setting that does\n");
        else if (r->dominated_by_default)
            printf(" the default dominates it, and so does %s, the fastest that does\n", fastest);
        else if (fastest)
            printf(" %s dominates it, the default does not\n", fastest);
        else
            printf(" no setting of skybake's dominates it\n");
        const struct sb_bench_row *best = rule_best(report, r);
        if (best && default_ratios(report, best, &time, &error))
            printf("    its rule's most accurate row here, %s, is %.3g off: the default takes %.3gx its time at "
                   "%.3gx its error\n",
                   best->label, best->error.max_rel, time, error);
    }
}

void sb_bench_print(const struct sb_bench_report *report, const struct sb_vk *vk, bool json)
{
    if (json) {
        sb_json_emit(stdout, report_json(report, vk));
        return;
    }
    printf("skybake bench on %s (%s); GPU time is the median of the repeats", vk->properties.deviceName,
           vk->driver_name);
    if (vk->properties.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU)
        printf(", the GPU kept busy %.0f ms before each setting and %.0f ms before each bake", SB_WARM_UP_MS,
               SB_KEEP_WARM_MS);
    printf("\n");
    printf("P: on the Pareto front; *: skybake's default\n");
    for (int w = 0; w < SB_BENCH_SWEEP_COUNT; w++) {
        if (!report->probe[w][0])
            continue;
        printf("\n%s (%s over %s; reference %.1f s)\n", sb_atmosphere_sweeps[w].name,
               sb_atmosphere_sweeps[w].error_name, report->probe[w], report->reference_s[w]);
        printf("  %-22s %7s %11s %10s %10s %10s  %s\n", "setting", "cost", "gpu ms", "max rel", "rms rel", "fp16 max",
               "");
        for (int i = 0; i < report->row_count; i++) {
            const struct sb_bench_row *r = &report->rows[i];
            if (r->sweep != (enum sb_bench_sweep)w)
                continue;
            printf("%c%c%-22s %7llu %11.4f %10.3g %10.3g %10.3g  %s\n", r->pareto ? 'P' : ' ',
                   r->is_default ? '*' : ' ', r->label, (unsigned long long)r->cost, r->gpu_ms, r->error.max_rel,
                   r->error.rms_rel, r->error_half.max_rel, r->anchor ? r->anchor : "");
        }
        print_anchors(report, w);
    }
    if (!report->cloud_row_count) {
        sb_bench_probes_print(report);
        sb_bench_reflection_print(report);
        return;
    }
    printf("\ncloud noise (the GPU against the CPU reference on one core, every value compared)\n");
    printf("  %-14s %-12s %11s %11s %14s %9s  %s\n", "product", "size", "gpu ms", "gpu ms min", "reference ms",
           "speedup", "values differing");
    double gpu = 0, ref = 0;
    for (int i = 0; i < report->cloud_row_count; i++) {
        const struct sb_bench_cloud_row *r = &report->cloud_rows[i];
        char size[48];
        snprintf(size, sizeof(size), "%ux%ux%u", r->shape[0], r->shape[1], r->shape[2]);
        printf("  %-14s %-12s %11.4f %11.4f %14.1f %9.1f  %llu of %llu\n", sb_product_name(r->product), size, r->gpu_ms,
               r->gpu_ms_min, r->reference_ms, r->reference_ms / fmax(r->gpu_ms, 1e-9),
               (unsigned long long)r->differing, (unsigned long long)r->values);
        gpu += r->gpu_ms;
        ref += r->reference_ms;
    }
    printf("  %-14s %-12s %11.4f %11s %14.1f %9.1f\n", "all", "", gpu, "", ref, ref / fmax(gpu, 1e-9));
    sb_bench_probes_print(report);
    sb_bench_reflection_print(report);
}

static enum sb_result write_text(const char *dir, const char *name, const char *text)
{
    char path[4096], tmp[4200];
    snprintf(path, sizeof(path), "%s/%s", dir, name);
    snprintf(tmp, sizeof(tmp), "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) {
        sb_error("%s: cannot write: %s", tmp, strerror(errno));
        return SB_ERR_IO;
    }
    bool ok = fputs(text, f) >= 0;
    ok = fclose(f) == 0 && ok;
    if (!ok || rename(tmp, path) != 0) {
        sb_error("%s: cannot write: %s", path, strerror(errno));
        unlink(tmp);
        return SB_ERR_IO;
    }
    return SB_OK;
}

/* A growing string for the CSV and the plot's script. */
struct text {
    char *data;
    size_t size, cap;
    bool failed;
};

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void
text_add(struct text *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0 || t->failed)
        return;
    if (t->size + (size_t)n + 1 > t->cap) {
        size_t cap = (t->cap + (size_t)n + 1) * 2;
        char *p = realloc(t->data, cap);
        if (!p) {
            t->failed = true;
            return;
        }
        t->data = p;
        t->cap = cap;
    }
    va_start(ap, fmt);
    vsnprintf(t->data + t->size, t->cap - t->size, fmt, ap);
    va_end(ap);
    t->size += (size_t)n;
}

static enum sb_result write_plot(const struct sb_bench_report *report, const struct sb_vk *vk, const char *dir)
{
    int panels = 0;
    for (int w = 0; w < SB_BENCH_SWEEP_COUNT; w++)
        panels += report->probe[w][0] != 0;
    struct text gp = {0};
    text_add(&gp, "# skybake bench: max relative error against GPU time; run with gnuplot in this directory\n");
    text_add(&gp, "set terminal svg size 1500,%d dynamic font 'sans,11'\nset output 'bench.svg'\n",
             panels > 3 ? 1000 : 520);
    text_add(&gp, "set datafile separator ','\nset termoption noenhanced\nset logscale xy\nset grid\n");
    text_add(&gp, "set key bottom left Left reverse font ',9'\n"
                  "set xlabel 'GPU ms (median)'\nset ylabel 'max rel error vs fp64'\n");
    text_add(&gp, "set multiplot layout %d,3 title 'skybake bench on %s'\n", panels > 3 ? 2 : 1,
             vk->properties.deviceName);
    for (int w = 0; w < SB_BENCH_SWEEP_COUNT; w++) {
        if (!report->probe[w][0])
            continue;
        /* columns of bench.csv: 1 sweep, 2 setting, 5 gpu_ms, 7 max_rel, 12 pareto, 13 anchor, 4 default */
        text_add(&gp, "set title '%s (%s)'\n", sb_atmosphere_sweeps[w].name, sb_atmosphere_sweeps[w].error_name);
        text_add(
            &gp,
            "plot 'bench_%s.csv' using 5:7 with points pt 7 ps 0.6 lc rgb '#7f7f7f' title 'settings', \\\n"
            "     '' using 5:($12 > 0 ? $7 : 1/0) smooth unique with linespoints pt 7 lw 2 lc rgb '#1f77b4' "
            "title 'Pareto front', \\\n"
            "     '' using 5:($13 > 0 ? $7 : 1/0) with points pt 9 ps 1.6 lc rgb '#d62728' title 'published', \\\n"
            "     '' using 5:($4 > 0 ? $7 : 1/0) with points pt 5 ps 1.2 lc rgb '#2ca02c' title 'skybake default', "
            "\\\n"
            "     '' using 5:7:2 with labels offset 0.6,0.5 left font ',8' notitle\n",
            sb_atmosphere_sweeps[w].name);
    }
    text_add(&gp, "unset multiplot\n");
    enum sb_result res = gp.failed ? SB_ERR_NOMEM : write_text(dir, "bench.gp", gp.data);
    free(gp.data);
    if (res)
        return res;

    pid_t pid = fork();
    if (pid < 0) {
        sb_error("cannot start gnuplot: %s", strerror(errno));
        return SB_ERR_IO;
    }
    if (pid == 0) {
        if (chdir(dir) == 0)
            execlp("gnuplot", "gnuplot", "bench.gp", (char *)NULL);
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        sb_error("%s/bench.gp: gnuplot failed (exit %d)%s; the CSV and JSON are written", dir,
                 WIFEXITED(status) ? WEXITSTATUS(status) : -1,
                 WIFEXITED(status) && WEXITSTATUS(status) == 127 ? " or is not installed (apt-get install gnuplot-nox)"
                                                                 : "");
        return SB_ERR_IO;
    }
    return SB_OK;
}

static void csv_row(struct text *t, const struct sb_bench_row *r)
{
    text_add(t, "%s,%s,%llu,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%u,%d,%d,\"%s\"\n", sb_atmosphere_sweeps[r->sweep].name,
             r->label, (unsigned long long)r->cost, r->is_default, r->gpu_ms, r->gpu_ms_min, r->error.max_rel,
             r->error.rms_rel, r->error_half.max_rel, r->error_half.rms_rel, r->error.count, r->pareto,
             r->anchor != NULL, r->anchor ? r->anchor : "");
}

enum sb_result sb_bench_write(const struct sb_bench_report *report, const struct sb_vk *vk, const char *dir)
{
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        sb_error("%s: cannot create: %s", dir, strerror(errno));
        return SB_ERR_IO;
    }
    static const char header[] = "sweep,setting,cost,default,gpu_ms,gpu_ms_min,max_rel,rms_rel,max_rel_fp16,"
                                 "rms_rel_fp16,values,pareto,anchor,anchor_name\n";
    struct text all = {0};
    text_add(&all, "%s", header);
    enum sb_result res = SB_OK;
    for (int w = 0; w < SB_BENCH_SWEEP_COUNT && !res; w++) {
        if (!report->probe[w][0])
            continue;
        struct text one = {0};
        text_add(&one, "%s", header);
        /* by time, so that the front's line runs left to right */
        int order[64], n = 0;
        for (int i = 0; i < report->row_count && n < 64; i++)
            if (report->rows[i].sweep == (enum sb_bench_sweep)w)
                order[n++] = i;
        for (int i = 1; i < n; i++)
            for (int j = i; j > 0 && report->rows[order[j]].gpu_ms < report->rows[order[j - 1]].gpu_ms; j--) {
                int tmp = order[j];
                order[j] = order[j - 1];
                order[j - 1] = tmp;
            }
        for (int i = 0; i < n; i++) {
            csv_row(&one, &report->rows[order[i]]);
            csv_row(&all, &report->rows[order[i]]);
        }
        char name[96];
        snprintf(name, sizeof(name), "bench_%s.csv", sb_atmosphere_sweeps[w].name);
        res = one.failed ? SB_ERR_NOMEM : write_text(dir, name, one.data);
        free(one.data);
    }
    if (!res)
        res = all.failed ? SB_ERR_NOMEM : write_text(dir, "bench.csv", all.data);
    free(all.data);
    if (!res && report->cloud_row_count) {
        struct text clouds = {0};
        text_add(&clouds, "product,width,height,depth,channels,gpu_ms,gpu_ms_min,reference_ms_one_core,values,"
                          "differing\n");
        for (int i = 0; i < report->cloud_row_count; i++) {
            const struct sb_bench_cloud_row *r = &report->cloud_rows[i];
            text_add(&clouds, "%s,%u,%u,%u,%u,%.6g,%.6g,%.6g,%llu,%llu\n", sb_product_name(r->product), r->shape[0],
                     r->shape[1], r->shape[2], r->channel_count, r->gpu_ms, r->gpu_ms_min, r->reference_ms,
                     (unsigned long long)r->values, (unsigned long long)r->differing);
        }
        res = clouds.failed ? SB_ERR_NOMEM : write_text(dir, "bench_clouds.csv", clouds.data);
        free(clouds.data);
    }
    if (!res && report->probe_row_count) {
        char path[4200];
        snprintf(path, sizeof(path), "%s/bench_probes.csv", dir);
        res = sb_bench_probes_csv(report, path);
    }
    if (!res && report->reflection_row_count) {
        char path[4200];
        snprintf(path, sizeof(path), "%s/bench_reflection.csv", dir);
        res = sb_bench_reflection_csv(report, path);
    }
    if (!res) {
        cJSON *root = report_json(report, vk);
        char *text = cJSON_Print(root);
        res = text ? write_text(dir, "bench.json", text) : SB_ERR_NOMEM;
        free(text);
        cJSON_Delete(root);
    }
    if (!res && report->row_count)
        res = write_plot(report, vk, dir);
    return res;
}
