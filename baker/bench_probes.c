/*
 * skybake bench --product sky_visibility: the probes' rays per second on
 * the device against Embree's on every core of this machine (the same
 * rays: every probe's Fibonacci set), and the bake's time, over the IFC
 * house of assimp-testmodels and a generated terrain of a million
 * triangles, 4096 probes each.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "bvh.h"
#include "embree_ref.h"
#include "log.h"
#include "load.h"
#include "mesh.h"
#include "parallel.h"
#include "raycast.h"
#include "sh.h"
#include "sky_bounce.h"
#include "sky_visibility.h"

#define BENCH_IFC_HOUSE "/usr/share/assimp/models/IFC/AC14-FZK-Haus.ifc"

enum sb_result sb_bench_terrain(uint32_t n, struct sb_mesh *mesh)
{
    uint32_t material;
    double albedo[3] = {0.2, 0.25, 0.15};
    enum sb_result res = sb_mesh_add_material(mesh, "terrain", albedo, &material);
    double size = 2000.0, step = size / (n - 1);
    for (uint32_t j = 0; j + 1 < n && !res; j++)
        for (uint32_t i = 0; i + 1 < n && !res; i++) {
            double p[4][3];
            for (int k = 0; k < 4; k++) {
                double x = -0.5 * size + (i + (k & 1)) * step, z = -0.5 * size + (j + (k >> 1)) * step;
                p[k][0] = x;
                p[k][1] = 40 * sin(x / 150) * cos(z / 170) + 12 * sin(x / 37 + z / 53) + 3 * cos(x / 9 - z / 11);
                p[k][2] = z;
            }
            res = sb_mesh_add_triangle(mesh, p[0], p[2], p[1], material, "terrain");
            if (!res)
                res = sb_mesh_add_triangle(mesh, p[1], p[2], p[3], material, "terrain");
        }
    return res;
}

double sb_bench_median(double *v, int n)
{
    for (int a = 1; a < n; a++)
        for (int b = a; b > 0 && v[b] < v[b - 1]; b--) {
            double t = v[b];
            v[b] = v[b - 1];
            v[b - 1] = t;
        }
    return v[n / 2];
}

/* Our build on every thread and on one, Embree's medium and high, the
 * median of three each; the last of ours in *bvh. */
static enum sb_result time_builds(const struct sb_mesh *mesh, struct sb_bench_probe_row *row, struct sb_bvh *bvh)
{
    double ours[3], one[3], medium[3], high[3];
    enum sb_result res = SB_OK;
    int all = row->bvh_threads = sb_parallel_threads();
    /* ours first: Embree's threads spin a while after its builds */
    for (int pass = 0; pass < 2 && !res; pass++) {
        sb_parallel_set_threads(pass ? all : 1);
        for (int k = 0; k < 3 && !res; k++) {
            double t0 = sb_now_s();
            res = sb_bvh_build(mesh, bvh);
            (pass ? ours : one)[k] = (sb_now_s() - t0) * 1e3;
            if (!res && (!pass || k < 2))
                sb_bvh_finish(bvh);
        }
    }
    for (int k = 0; k < 3 && !res; k++) {
        medium[k] = sb_embree_build_ms(mesh, RTC_BUILD_QUALITY_MEDIUM);
        high[k] = sb_embree_build_ms(mesh, RTC_BUILD_QUALITY_HIGH);
    }
    if (res)
        return res;
    row->bvh_ms = sb_bench_median(ours, 3);
    row->bvh_one_thread_ms = sb_bench_median(one, 3);
    row->embree_medium_ms = sb_bench_median(medium, 3);
    row->embree_high_ms = sb_bench_median(high, 3);
    return SB_OK;
}

static enum sb_result bench_one(struct sb_vk *vk, const char *name, struct sb_mesh *mesh, uint32_t rays_per_probe,
                                int repeat, struct sb_bench_probe_row *row)
{
    memset(row, 0, sizeof(*row));
    snprintf(row->scene, sizeof(row->scene), "%s", name);
    row->triangles = mesh->triangle_count;
    row->rays_per_probe = rays_per_probe;
    struct sb_bvh bvh = {0};
    struct sb_raycaster *rc = NULL;
    struct sb_embree e = {0};
    float *positions = NULL, *out = NULL, *rays = NULL, *hits = NULL;
    enum sb_result res = time_builds(mesh, row, &bvh);
    if (res || (res = sb_raycaster_create(vk, &bvh, &rc)))
        goto done;
    /* 16^3 probes over the bounds, from 2 m above its bottom */
    float lo[3], hi[3];
    sb_mesh_bounds(mesh, lo, hi);
    lo[1] += 2.0f;
    const uint32_t side = 16, count = side * side * side;
    row->probes = count;
    positions = malloc((size_t)count * 3 * sizeof(float));
    out = malloc((size_t)count * SB_VISIBILITY_FLOATS * sizeof(float));
    if (!positions || !out) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    for (uint32_t i = 0; i < count; i++) {
        uint32_t c[3] = {i % side, i / side % side, i / side / side};
        for (int k = 0; k < 3; k++)
            positions[3 * (size_t)i + k] = lo[k] + (hi[k] - lo[k]) * (c[k] + 0.5f) / side;
    }
    struct sb_sky_visibility_params params = {.ray_count = rays_per_probe};
    struct sb_sky_bounce_params bounce = {.ray_count = rays_per_probe >= 512 ? rays_per_probe / 8 : 64,
                                          .secondary = rays_per_probe >= 256 ? rays_per_probe / 32 : 8};
    double *times = calloc((size_t)repeat, sizeof(double)), *bounce_times = calloc((size_t)repeat, sizeof(double));
    float *bounced = malloc((size_t)count * SB_BOUNCE_FLOATS * sizeof(float));
    if (!times || !bounce_times || !bounced) {
        free(times);
        free(bounce_times);
        free(bounced);
        res = SB_ERR_NOMEM;
        goto done;
    }
    struct sb_surfaces surfaces = {0};
    res = sb_surfaces_create(vk, mesh, 1, &surfaces);
    for (int k = repeat >= 3 ? -1 : 0; k < repeat && !res; k++) {
        double ms, bms = 0;
        res = sb_warm_up(vk, k <= 0 ? SB_WARM_UP_MS : SB_KEEP_WARM_MS);
        if (!res)
            res = sb_sky_visibility_bake(rc, positions, count, &params, out, &ms);
        if (!res)
            res = sb_sky_bounce_bake(rc, &surfaces, positions, NULL, count, &bounce, bounced, &bms, NULL);
        if (k >= 0) {
            times[k] = ms;
            bounce_times[k] = bms;
        }
    }
    if (!res) {
        row->gpu_ms = sb_bench_median(times, repeat);
        row->bounce_ms = sb_bench_median(bounce_times, repeat);
        row->bounce_rays = bounce.ray_count;
        row->bounce_secondary = bounce.secondary;
    }
    free(times);
    free(bounce_times);
    free(bounced);
    sb_surfaces_destroy(vk, &surfaces);
    if (res)
        goto done;
    row->rays = (uint64_t)count * rays_per_probe;
    row->gpu_rays_per_s = row->rays / (row->gpu_ms * 1e-3);

    /* Embree: the same rays, on every core */
    if (!sb_embree_create(mesh, &e)) {
        sb_error("bench: Embree refused the %s mesh", name);
        res = SB_ERR_MESH;
        goto done;
    }
    const uint32_t chunk = 64 * rays_per_probe; /* 64 probes a cast */
    rays = malloc((size_t)chunk * 8 * sizeof(float));
    hits = malloc((size_t)chunk * 4 * sizeof(float));
    if (!rays || !hits) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    for (uint32_t first = 0; first < count; first += 64) {
        uint32_t probes = count - first < 64 ? count - first : 64;
        for (uint32_t p = 0; p < probes; p++)
            sb_probe_rays(&positions[3 * (size_t)(first + p)], rays_per_probe, 1e-4f,
                          &rays[8 * (size_t)p * rays_per_probe]);
        row->embree_s += sb_embree_cast(&e, rays, probes * rays_per_probe, hits);
        for (uint32_t p = 0; p < probes; p++) {
            uint32_t n = 0;
            for (uint32_t r = 0; r < rays_per_probe; r++) {
                uint32_t t;
                memcpy(&t, &hits[4 * ((size_t)p * rays_per_probe + r) + 1], sizeof(t));
                n += t != SB_BVH_MISS;
            }
            double gpu_hits = out[SB_VISIBILITY_FLOATS * (size_t)(first + p) + SB_PROBE_SH + 1] * rays_per_probe;
            row->hits_differ += (uint64_t)fabs(gpu_hits - n);
        }
    }
    row->embree_threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    row->embree_rays_per_s = row->rays / row->embree_s;
    sb_info("%s: %u triangles, %u probes x %u rays: gpu %.3f ms (%.3g Mrays/s), Embree %.3f s on %d threads (%.3g "
            "Mrays/s); %llu rays' hit or miss differ",
            name, row->triangles, count, rays_per_probe, row->gpu_ms, row->gpu_rays_per_s * 1e-6, row->embree_s,
            row->embree_threads, row->embree_rays_per_s * 1e-6, (unsigned long long)row->hits_differ);
done:
    if (e.device)
        sb_embree_destroy(&e);
    free(rays);
    free(hits);
    free(positions);
    free(out);
    sb_raycaster_destroy(&rc);
    sb_bvh_finish(&bvh);
    return res;
}

enum sb_result sb_bench_probes(struct sb_vk *vk, const struct sb_bench_params *params, struct sb_bench_report *report)
{
    uint32_t rays = params->quick ? 256 : 2048;
    int repeat = params->repeat > 0 ? params->repeat : 1;
    struct sb_mesh mesh = {0};
    enum sb_result res = SB_OK;
    if (access(BENCH_IFC_HOUSE, R_OK) == 0) {
        if (!(res = sb_mesh_load(BENCH_IFC_HOUSE, NULL, &mesh)))
            res = bench_one(vk, "ifc-house", &mesh, rays, repeat, &report->probe_rows[report->probe_row_count++]);
        sb_mesh_finish(&mesh);
    } else {
        sb_warn("bench: %s is missing (Debian's assimp-testmodels): no IFC house row", BENCH_IFC_HOUSE);
    }
    if (!res && !(res = sb_bench_terrain(params->quick ? 201 : 709, &mesh)))
        res = bench_one(vk, params->quick ? "terrain-80k" : "terrain-1M", &mesh, rays, repeat,
                        &report->probe_rows[report->probe_row_count++]);
    sb_mesh_finish(&mesh);
    return res;
}

void sb_bench_probes_print(const struct sb_bench_report *report)
{
    if (!report->probe_row_count)
        return;
    printf("\nsky visibility (4096 probes; Embree casts the same rays on every core of this machine) and sky bounce "
           "(the same probes, %u x %u rays)\n",
           report->probe_rows[0].bounce_rays, report->probe_rows[0].bounce_secondary);
    printf("%-12s %10s %7s %6s %11s %12s %11s %12s %9s %11s\n", "scene", "triangles", "probes", "rays", "gpu ms",
           "gpu Mrays/s", "embree s", "embree Mr/s", "differ", "bounce ms");
    for (int i = 0; i < report->probe_row_count; i++) {
        const struct sb_bench_probe_row *r = &report->probe_rows[i];
        printf("%-12s %10u %7u %6u %11.3f %12.3f %11.3f %12.3f %9llu %11.3f\n", r->scene, r->triangles, r->probes,
               r->rays_per_probe, r->gpu_ms, r->gpu_rays_per_s * 1e-6, r->embree_s, r->embree_rays_per_s * 1e-6,
               (unsigned long long)r->hits_differ, r->bounce_ms);
    }
    printf("\nBVH build, wall ms (median of 3): ours on %d threads and on one, Embree's binned SAH (medium) and "
           "spatial splits (high) on %d\n",
           report->probe_rows[0].bvh_threads, report->probe_rows[0].embree_threads);
    printf("%-12s %10s %10s %10s %10s %10s %9s\n", "scene", "triangles", "ours", "ours 1t", "medium", "high",
           "/medium");
    for (int i = 0; i < report->probe_row_count; i++) {
        const struct sb_bench_probe_row *r = &report->probe_rows[i];
        printf("%-12s %10u %10.1f %10.1f %10.1f %10.1f %9.2f\n", r->scene, r->triangles, r->bvh_ms,
               r->bvh_one_thread_ms, r->embree_medium_ms, r->embree_high_ms, r->bvh_ms / r->embree_medium_ms);
    }
}

enum sb_result sb_bench_probes_csv(const struct sb_bench_report *report, const char *path)
{
    if (!report->probe_row_count)
        return SB_OK;
    FILE *f = fopen(path, "w");
    if (!f) {
        sb_error("%s: cannot write", path);
        return SB_ERR_IO;
    }
    fprintf(f, "scene,triangles,probes,rays_per_probe,bvh_ms,bvh_threads,bvh_one_thread_ms,embree_medium_build_ms,"
               "embree_high_build_ms,gpu_ms,gpu_rays_per_s,embree_s,embree_threads,"
               "embree_rays_per_s,hits_differ,bounce_rays,bounce_secondary,bounce_gpu_ms\n");
    for (int i = 0; i < report->probe_row_count; i++) {
        const struct sb_bench_probe_row *r = &report->probe_rows[i];
        fprintf(f, "%s,%u,%u,%u,%.6g,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.6g,%llu,%u,%u,%.6g\n", r->scene,
                r->triangles, r->probes, r->rays_per_probe, r->bvh_ms, r->bvh_threads, r->bvh_one_thread_ms,
                r->embree_medium_ms, r->embree_high_ms, r->gpu_ms, r->gpu_rays_per_s, r->embree_s, r->embree_threads,
                r->embree_rays_per_s, (unsigned long long)r->hits_differ, r->bounce_rays, r->bounce_secondary,
                r->bounce_ms);
    }
    return fclose(f) == 0 ? SB_OK : SB_ERR_IO;
}
