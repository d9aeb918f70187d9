/*
 * skybake bench: speed against error. For each atmosphere product, bake it
 * with each setting of a sweep (quadratures, sample and direction counts,
 * resolution where it matters), time it on the device (GPU timestamps, the
 * median of repeated bakes) and measure its max and RMS error against the
 * fp64 reference (accuracy.h). The published settings are rows of their
 * own: Hillaire 2020's 40-step march and Bruneton 2017's 500-step
 * trapezoid for transmittance. The Pareto front (no other setting both
 * faster and more accurate) is marked, and the default setting's error in
 * half precision is reported (what fp16 storage would cost).
 *
 * For the cloud noise, which matches its reference bit for bit, speed
 * alone: each product's bake timed on the device, against the CPU
 * reference on one core over every texel, with the values compared.
 */
#ifndef SB_BAKER_BENCH_H
#define SB_BAKER_BENCH_H

#include <stdbool.h>

#include "accuracy.h"
#include "atmosphere.h"
#include "context.h"
#include "mesh.h"
#include "scene.h"

/* The sweeps: one per product, and one of transmittance's resolution
 * measured by its lookup error. */
enum sb_bench_sweep {
    SB_BENCH_TRANSMITTANCE,
    SB_BENCH_TRANSMITTANCE_RESOLUTION,
    SB_BENCH_MULTISCATTERING,
    SB_BENCH_IRRADIANCE_GROUND,
    SB_BENCH_IRRADIANCE_SKY,
    SB_BENCH_SWEEP_COUNT,
};

struct sb_bench_row {
    enum sb_bench_sweep sweep;
    struct sb_atmosphere_settings settings;
    char label[48];
    const char *anchor; /* the published setting this row reproduces, or NULL */
    bool ours;          /* skybake's quadrature, not a published rule or a variant of one */
    bool is_default;    /* what skybake bakes without a tolerance */
    uint64_t cost;      /* sb_atmosphere_settings_cost */
    double gpu_ms;      /* median over the repeats */
    double gpu_ms_min;
    struct sb_error error;
    struct sb_error error_half; /* the same bake stored in half precision */
    bool pareto;
    /* An anchor row against skybake's settings of its sweep, measured in the
     * same run: the fastest of them that dominates it (at most its time and
     * its error, less of one), or -1; and whether the default does. */
    int dominated_by; /* an index into the report's rows */
    bool dominated_by_default;
};

/* A cloud product: the device against the CPU reference on one core. */
struct sb_bench_cloud_row {
    enum sb_product_id product;
    uint32_t shape[3], channel_count;
    double gpu_ms, gpu_ms_min;  /* median, min over the repeats */
    double reference_ms;        /* sb_cloud_ref over every texel, one thread */
    uint64_t values, differing; /* the GPU's values against the reference's */
};

/* sky_visibility: rays per second on the device and Embree's (bench_probes.c). */
struct sb_bench_probe_row {
    char scene[32];
    uint32_t triangles, probes, rays_per_probe;
    /* BVH builds, wall ms, each the median of three: ours on every thread
     * (bvh_threads) and on one, Embree's binned SAH (medium quality) and
     * its spatial splits (high) on every core, all in the same run. */
    double bvh_ms, bvh_one_thread_ms, embree_medium_ms, embree_high_ms;
    int bvh_threads;
    double gpu_ms, gpu_rays_per_s; /* the bake (median of the repeats) */
    double embree_s, embree_rays_per_s;
    int embree_threads;
    uint64_t rays, hits_differ; /* rays whose hit or miss differ, summed over probes */
    uint32_t bounce_rays, bounce_secondary;
    double bounce_ms; /* sky_bounce at the same probes, the defaults (median of the repeats) */
};

/* reflection_cubes' prefilter (bench_reflection.c): one setting's GPU time
 * and its error against the fp64 reference per mip. */
#define SB_BENCH_MAX_MIPS 12
struct sb_bench_reflection_row {
    char label[48];
    const char *anchor; /* the published setting this row reproduces, or NULL */
    bool is_default, pareto;
    uint32_t samples_first, samples_last; /* a texel's at mip 1 and at the last */
    double gpu_ms, gpu_ms_min;
    double rms[SB_BENCH_MAX_MIPS], max[SB_BENCH_MAX_MIPS]; /* relative, per mip (0: the source) */
    double worst_rms, worst_max;                           /* over mips 1.. */
};

struct sb_bench_params {
    bool sweeps[SB_BENCH_SWEEP_COUNT]; /* which to run */
    bool clouds[SB_PRODUCT_COUNT];     /* which cloud products to time */
    bool probes;                       /* sky_visibility */
    bool reflection;                   /* reflection_cubes' prefilter */
    uint32_t reflection_face;          /* its cube's face size (0: 256, 64 with quick) */
    struct sb_cloud_params cloud_params;
    int repeat; /* bakes per setting; the median is reported */
    bool quick; /* only the settings marked quick (meson's benchmark) */
};

struct sb_bench_report {
    int row_count;
    struct sb_bench_row *rows;
    double reference_s[SB_BENCH_SWEEP_COUNT]; /* wall time of each fp64 reference */
    char probe[SB_BENCH_SWEEP_COUNT][96];
    int cloud_row_count;
    struct sb_bench_cloud_row cloud_rows[SB_PRODUCT_COUNT - SB_ATMOSPHERE_PRODUCT_COUNT];
    int probe_row_count;
    struct sb_bench_probe_row probe_rows[2];
    int reflection_row_count;
    struct sb_bench_reflection_row reflection_rows[16];
    uint32_t reflection_face, reflection_levels;
    double reflection_capture_ms, reflection_reference_s;
};

/* Every bench keeps the GPU's clocks up before a timed bake (sb_warm_up,
 * vulkan/compute.h): SB_WARM_UP_MS before a setting's first bake and its
 * first timed one, SB_KEEP_WARM_MS before the others. */

/* bench_probes.c: also the terrain (rolling hills over 2 km, (n - 1)^2 x 2
 * triangles) and the median of n values (sorted in place), which the benches
 * share (their clock is sb_now_s, formats/log.h). */
enum sb_result sb_bench_terrain(uint32_t n, struct sb_mesh *mesh);
double sb_bench_median(double *v, int n);
/* bench_reflection.c */
enum sb_result sb_bench_reflection(struct sb_vk *vk, const struct sb_atmosphere_params *atmosphere,
                                   const struct sb_bench_params *params, struct sb_bench_report *report);
void sb_bench_reflection_print(const struct sb_bench_report *report);
enum sb_result sb_bench_reflection_csv(const struct sb_bench_report *report, const char *path);
/* bench_probes.c */
enum sb_result sb_bench_probes(struct sb_vk *vk, const struct sb_bench_params *params, struct sb_bench_report *report);
void sb_bench_probes_print(const struct sb_bench_report *report);
enum sb_result sb_bench_probes_csv(const struct sb_bench_report *report, const char *path);

bool sb_bench_sweep_from_name(const char *name, enum sb_bench_sweep *sweep);

enum sb_result sb_bench_run(struct sb_vk *vk, const struct sb_atmosphere_params *atmosphere,
                            const struct sb_bench_params *params, struct sb_bench_report *report);
void sb_bench_report_finish(struct sb_bench_report *report);

/* Print the tables (text) or the report as JSON on stdout. */
void sb_bench_print(const struct sb_bench_report *report, const struct sb_vk *vk, bool json);

/* Write bench.csv, bench.json, bench.gp and bench.svg (drawn by gnuplot;
 * the CSV and the plot when an atmosphere sweep ran) and bench_clouds.csv
 * (when cloud products were timed) into dir, created if missing. */
enum sb_result sb_bench_write(const struct sb_bench_report *report, const struct sb_vk *vk, const char *dir);

#endif
