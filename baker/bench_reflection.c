/*
 * skybake bench --product reflection_cubes: the prefilter's GPU time
 * against its error, per setting, on one cube captured above the bench's
 * terrain (rolling hills, their shadows and the sky) at the face size the
 * issue's goal names (256; 64 with --quick). The error of each mip is
 * measured against the fp64 dense integral (reflection_ref.c) at every
 * face's corners and a lattice along its edges and inside; skybake's
 * schedule (samples doubling per mip, no lod bias) at several sample
 * counts, and two published settings as rows of their own: Karis 2013
 * (1024 samples at every mip, every sample from the source itself) and
 * Filament's cmgen (1024 at every mip, filtered with its lod bias of 1).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "bvh.h"
#include "cube.h"
#include "exr.h"
#include "log.h"
#include "parallel.h"
#include "reflection.h"

struct ref_texel {
    uint32_t level, face, x, y;
    double value[3];
};

struct ref_job {
    const float *level0;
    uint32_t n, levels;
    struct ref_texel *texels;
};

static void reference_one(void *user, int i)
{
    struct ref_job *job = user;
    struct ref_texel *t = &job->texels[i];
    uint32_t m = job->n >> t->level;
    double d[3];
    sb_cube_texel_direction((int)t->face, m, t->x, t->y, d);
    /* Pieces fine enough for the lobe: a mip-1 lobe spans a few source texels. */
    int sub = t->level == 1 ? 4 : t->level == 2 ? 2 : 1;
    sb_reflection_reference(job->level0, job->n, d, sb_reflection_level_roughness(t->level, job->levels), sub,
                            t->value);
}

/* Corners, every (m / 8)th texel along the edges and a lattice inside. */
static uint32_t pick_texels(uint32_t n, uint32_t levels, struct ref_texel *out)
{
    uint32_t count = 0;
    for (uint32_t l = 1; l < levels; l++) {
        uint32_t m = n >> l, stride = m > 8 ? m / 8 : 1;
        for (uint32_t f = 0; f < 6; f++)
            for (uint32_t y = 0; y < m; y++)
                for (uint32_t x = 0; x < m; x++) {
                    bool edge = x == 0 || y == 0 || x == m - 1 || y == m - 1;
                    bool corner = (x == 0 || x == m - 1) && (y == 0 || y == m - 1);
                    if (!corner && (x % stride || y % stride) && !(edge && (x + y) % stride == 0))
                        continue;
                    if (out)
                        out[count] = (struct ref_texel){.level = l, .face = f, .x = x, .y = y};
                    count++;
                }
    }
    return count;
}

static void measure(const float *chain, uint32_t n, const struct ref_texel *texels, uint32_t count,
                    struct sb_bench_reflection_row *row)
{
    double sum[SB_BENCH_MAX_MIPS] = {0};
    int values[SB_BENCH_MAX_MIPS] = {0};
    for (uint32_t i = 0; i < count; i++) {
        const struct ref_texel *t = &texels[i];
        uint32_t m = n >> t->level;
        const float *got =
            chain + 4 * (sb_cube_level_offset(n, t->level) + (size_t)t->face * m * m + (size_t)t->y * m + t->x);
        for (int c = 0; c < 3; c++) {
            double rel = fabs(got[c] - t->value[c]) / fmax(fabs(t->value[c]), 1e-6);
            sum[t->level] += rel * rel;
            values[t->level]++;
            row->max[t->level] = fmax(row->max[t->level], rel);
        }
    }
    row->worst_rms = row->worst_max = 0;
    for (int l = 1; l < SB_BENCH_MAX_MIPS; l++)
        if (values[l]) {
            row->rms[l] = sqrt(sum[l] / values[l]);
            row->worst_rms = fmax(row->worst_rms, row->rms[l]);
            row->worst_max = fmax(row->worst_max, row->max[l]);
        }
}

/* The cube: the sky-only capture for the light surfaces see, then the
 * world's from 20 m above the terrain's middle, the sun 30 degrees up. */
static enum sb_result capture(struct sb_vk *vk, const struct sb_atmosphere_params *atmosphere, uint32_t n,
                              float *level0, double *ms)
{
    struct sb_atmosphere_baker *atm = NULL;
    struct sb_mesh mesh = {0};
    struct sb_bvh bvh = {0};
    struct sb_raycaster *rc = NULL;
    struct sb_image lut = {0};
    static const enum sb_product_id inputs[] = {SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_MULTISCATTERING,
                                                SB_PRODUCT_IRRADIANCE_GROUND};
    enum sb_result res = sb_atmosphere_baker_create(vk, atmosphere, &atm);
    for (size_t i = 0; i < sizeof(inputs) / sizeof(inputs[0]) && !res; i++) {
        res = sb_atmosphere_bake(atm, inputs[i], NULL, &lut, NULL, NULL);
        sb_image_finish(&lut);
    }
    struct sb_surfaces surfaces = {0};
    if (!res && !(res = sb_bench_terrain(257, &mesh)) && !(res = sb_bvh_build(&mesh, &bvh)) &&
        !(res = sb_raycaster_create(vk, &bvh, &rc)))
        res = sb_surfaces_create(vk, &mesh, 1, &surfaces);
    struct sb_capture_params cp = {.origin_m = {0, 23, 0}, .altitude_km = 0.023, .face_size = n, .ambient_rays = 32};
    double el = 30 * M_PI / 180, az = 150 * M_PI / 180;
    cp.sun[0] = cos(el) * sin(az);
    cp.sun[1] = sin(el);
    cp.sun[2] = -cos(el) * cos(az);
    struct sb_capture_inputs sky = {.atmosphere = atm},
                             world = {.atmosphere = atm, .rc = rc, .surfaces = &surfaces};
    if (!res && !(res = sb_reflection_capture(vk, &sky, &cp, level0, NULL, NULL))) {
        sb_reflection_sh(level0, n, 0, cp.sky_sh);
        res = sb_reflection_capture(vk, &world, &cp, level0, NULL, ms);
    }
    sb_surfaces_destroy(vk, &surfaces);
    sb_raycaster_destroy(&rc);
    sb_bvh_finish(&bvh);
    sb_mesh_finish(&mesh);
    sb_atmosphere_baker_destroy(&atm);
    return res;
}

enum sb_result sb_bench_reflection(struct sb_vk *vk, const struct sb_atmosphere_params *atmosphere,
                                   const struct sb_bench_params *params, struct sb_bench_report *report)
{
    uint32_t n = params->reflection_face ? params->reflection_face : params->quick ? 64 : 256;
    uint32_t levels = sb_cube_levels(n);
    int repeat = params->repeat > 0 ? params->repeat : 3;
    if (n < 16 || n > 1024 || (n & (n - 1)) || levels > SB_BENCH_MAX_MIPS) {
        sb_error("bench: a reflection cube of %u texels a face; a power of two in [16, 1024]", n);
        return SB_ERR_OUT_OF_RANGE;
    }
    report->reflection_face = n;
    report->reflection_levels = levels;
    float *level0 = malloc((size_t)6 * n * n * 4 * sizeof(float));
    float *chain = malloc(sb_cube_level_offset(n, levels) * 4 * sizeof(float));
    uint32_t count = pick_texels(n, levels, NULL);
    struct ref_texel *texels = calloc(count, sizeof(*texels));
    double *times = malloc((size_t)repeat * sizeof(double));
    enum sb_result res = level0 && chain && texels && times ? SB_OK : SB_ERR_NOMEM;
    if (!res)
        res = capture(vk, atmosphere, n, level0, &report->reflection_capture_ms);
    if (res)
        goto done;
    struct sb_reflection_kernels kernels = {0};
    pick_texels(n, levels, texels);
    double t0 = sb_now_s();
    struct ref_job job = {.level0 = level0, .n = n, .levels = levels, .texels = texels};
    sb_parallel_for((int)count, reference_one, &job);
    report->reflection_reference_s = sb_now_s() - t0;
    sb_info("reflection_cubes: the fp64 reference at %u texels of %u levels took %.1f s", count, levels - 1,
            report->reflection_reference_s);

    static const struct {
        uint32_t samples;
        bool quick, constant, unfiltered;
        float bias;
        const char *anchor;
    } settings[] = {
        {16, false, false, false, 0, NULL},
        {32, true, false, false, 0, NULL},
        {64, false, false, false, 0, NULL},
        {128, true, false, false, 0, NULL},
        {256, false, false, false, 0, NULL},
        {512, true, false, false, 0, NULL},
        {1024, false, false, false, 0, NULL},
        {2048, false, false, false, 0, NULL},
        {1024, true, true, true, 0, "Karis 2013 (UE4): 1024 samples every mip, unfiltered"},
        {1024, true, true, false, 1, "Filament cmgen: 1024 samples every mip, lod bias 1"},
    };
    for (size_t s = 0; s < sizeof(settings) / sizeof(settings[0]) && !res; s++) {
        if (params->quick && !settings[s].quick)
            continue;
        struct sb_bench_reflection_row *row = &report->reflection_rows[report->reflection_row_count];
        memset(row, 0, sizeof(*row));
        const struct sb_prefilter_params pp = {.samples = settings[s].samples,
                                               .constant_samples = settings[s].constant,
                                               .lod_bias = settings[s].bias,
                                               .unfiltered = settings[s].unfiltered,
                                               .kernels = &kernels};
        for (int k = 0; k < repeat && !res; k++) {
            res = sb_warm_up(vk, k == 0 ? SB_WARM_UP_MS : SB_KEEP_WARM_MS);
            if (!res)
                res = sb_reflection_prefilter(vk, level0, n, &pp, chain, &times[k]);
        }
        if (res)
            break;
        row->gpu_ms_min = times[0];
        for (int k = 1; k < repeat; k++)
            row->gpu_ms_min = fmin(row->gpu_ms_min, times[k]);
        row->gpu_ms = sb_bench_median(times, repeat);
        row->anchor = settings[s].anchor;
        row->is_default = !row->anchor && settings[s].samples == 512;
        row->samples_first = settings[s].samples;
        row->samples_last = pp.constant_samples ? pp.samples : sb_reflection_level_samples(pp.samples, levels - 1);
        if (row->anchor)
            snprintf(row->label, sizeof(row->label), "%s", settings[s].unfiltered ? "karis2013" : "filament");
        else
            snprintf(row->label, sizeof(row->label), "ggx%u", settings[s].samples);
        measure(chain, n, texels, count, row);
        report->reflection_row_count++;
        sb_info("reflection_cubes %-10s %10.3f ms  worst mip rms %.3g max %.3g", row->label, row->gpu_ms,
                row->worst_rms, row->worst_max);
    }
    sb_reflection_kernels_destroy(vk, &kernels);
    /* The Pareto front: no other row both faster and more accurate. */
    for (int i = 0; i < report->reflection_row_count; i++) {
        struct sb_bench_reflection_row *a = &report->reflection_rows[i];
        a->pareto = true;
        for (int j = 0; j < report->reflection_row_count; j++) {
            const struct sb_bench_reflection_row *b = &report->reflection_rows[j];
            if (j != i && b->gpu_ms <= a->gpu_ms && b->worst_rms <= a->worst_rms &&
                (b->gpu_ms < a->gpu_ms || b->worst_rms < a->worst_rms))
                a->pareto = false;
        }
    }
done:
    free(level0);
    free(chain);
    free(texels);
    free(times);
    return res;
}

void sb_bench_reflection_print(const struct sb_bench_report *report)
{
    if (!report->reflection_row_count)
        return;
    printf("\nreflection_cubes: the prefilter of one %u^2 cube (%u mips), captured above the terrain in %.3f ms; "
           "error against the fp64 dense integral (%.1f s), relative, per mip\n",
           report->reflection_face, report->reflection_levels, report->reflection_capture_ms,
           report->reflection_reference_s);
    printf("  %-10s %8s %11s %11s %10s %10s  %s\n", "setting", "samples", "gpu ms", "gpu ms min", "worst rms",
           "worst max", "rms per mip (1..)");
    for (int i = 0; i < report->reflection_row_count; i++) {
        const struct sb_bench_reflection_row *r = &report->reflection_rows[i];
        char samples[32], per_mip[256] = "";
        snprintf(samples, sizeof(samples), "%u-%u", r->samples_first, r->samples_last);
        for (uint32_t l = 1; l < report->reflection_levels; l++) {
            size_t len = strlen(per_mip);
            snprintf(per_mip + len, sizeof(per_mip) - len, "%s%.2g", l > 1 ? " " : "", r->rms[l]);
        }
        printf("%c%c%-10s %8s %11.4f %11.4f %10.3g %10.3g  %s%s%s\n", r->pareto ? 'P' : ' ', r->is_default ? '*' : ' ',
               r->label, samples, r->gpu_ms, r->gpu_ms_min, r->worst_rms, r->worst_max, per_mip, r->anchor ? "  " : "",
               r->anchor ? r->anchor : "");
    }
    printf("  P: on the Pareto front (time against worst-mip rms); *: skybake's default (reflections.samples 512)\n");
}

enum sb_result sb_bench_reflection_csv(const struct sb_bench_report *report, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        sb_error("%s: cannot write", path);
        return SB_ERR_IO;
    }
    fprintf(f, "setting,face,samples_mip1,samples_last,gpu_ms,gpu_ms_min,worst_rms,worst_max,default,pareto,anchor");
    for (uint32_t l = 1; l < report->reflection_levels; l++)
        fprintf(f, ",rms_mip%u,max_mip%u", l, l);
    fprintf(f, "\n");
    for (int i = 0; i < report->reflection_row_count; i++) {
        const struct sb_bench_reflection_row *r = &report->reflection_rows[i];
        fprintf(f, "%s,%u,%u,%u,%.6g,%.6g,%.6g,%.6g,%d,%d,\"%s\"", r->label, report->reflection_face, r->samples_first,
                r->samples_last, r->gpu_ms, r->gpu_ms_min, r->worst_rms, r->worst_max, r->is_default, r->pareto,
                r->anchor ? r->anchor : "");
        for (uint32_t l = 1; l < report->reflection_levels; l++)
            fprintf(f, ",%.6g,%.6g", r->rms[l], r->max[l]);
        fprintf(f, "\n");
    }
    return fclose(f) == 0 ? SB_OK : SB_ERR_IO;
}
