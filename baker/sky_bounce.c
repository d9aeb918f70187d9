#include "sky_bounce.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "parallel.h"
#include "probe_bounce.spv.h"
#include "probe_bounce_instanced.spv.h"
#include "probe_bounce_sun.spv.h"
#include "probe_bounce_sun_instanced.spv.h"

_Static_assert(SB_SUN_BOUNCE_CHANNEL_COUNT == SB_BOUNCE_SUN_TABLE && SB_SUN_DIRECTIONS == 144,
               "sun_bounce's channels (probes.h) name the sun table's 144 directions and its shape");

struct sb_pipeline_params sb_sky_bounce_kernel(bool instanced, bool sun)
{
    struct sb_pipeline_params p = {
        .spirv = instanced ? sb_spv_probe_bounce_instanced : sb_spv_probe_bounce,
        .spirv_size = instanced ? sizeof(sb_spv_probe_bounce_instanced) : sizeof(sb_spv_probe_bounce),
        .binding_count = SB_BOUNCE_BINDING_COUNT,
        .push_size = sizeof(struct sb_bounce_push),
        .name = "sky bounce",
    };
    if (sun) {
        p.spirv = instanced ? sb_spv_probe_bounce_sun_instanced : sb_spv_probe_bounce_sun;
        p.spirv_size = instanced ? sizeof(sb_spv_probe_bounce_sun_instanced) : sizeof(sb_spv_probe_bounce_sun);
        p.name = "sun bounce";
    }
    return p;
}

/* (I - M)^-1 of one channel's operator, by Gauss-Jordan with partial
 * pivots; false when M's largest row sum is 1 or more (the series might
 * not converge: it is summed term by term instead) or the inverse is not
 * finite. */
static bool every_bounce(double m[SB_BOUNCE_SH][SB_BOUNCE_SH], double inverse[SB_BOUNCE_SH][SB_BOUNCE_SH])
{
    enum { S = SB_BOUNCE_SH };
    double a[S][2 * S], norm = 0;
    for (int i = 0; i < S; i++) {
        double row = 0;
        for (int j = 0; j < S; j++) {
            a[i][j] = (i == j) - m[i][j];
            a[i][S + j] = i == j;
            row += fabs(m[i][j]);
        }
        norm = fmax(norm, row);
    }
    if (!(norm < 1))
        return false;
    for (int c = 0; c < S; c++) {
        int pivot = c;
        for (int i = c + 1; i < S; i++)
            if (fabs(a[i][c]) > fabs(a[pivot][c]))
                pivot = i;
        for (int j = 0; j < 2 * S; j++) {
            double t = a[c][j];
            a[c][j] = a[pivot][j];
            a[pivot][j] = t;
        }
        for (int i = 0; i < S; i++)
            if (i != c) {
                double f = a[i][c] / a[c][c];
                for (int j = 0; j < 2 * S; j++)
                    a[i][j] -= f * a[c][j];
            }
    }
    for (int i = 0; i < S; i++)
        for (int j = 0; j < S; j++) {
            inverse[i][j] = a[i][S + j] / a[i][i];
            if (!isfinite(inverse[i][j]))
                return false;
        }
    return true;
}

/* Where column k of the transfer (k < SB_PROBE_SH: the light's SH; then
 * the sun table's directions) is in the kernel's output for m, c. */
static size_t column_at(int m, int k, int c)
{
    return k < SB_PROBE_SH ? (size_t)(m * SB_PROBE_SH + k) * 3 + c
                           : SB_BOUNCE_KERNEL_FLOATS + (size_t)((k - SB_PROBE_SH) * SB_BOUNCE_SH + m) * 3 + c;
}

uint32_t sb_sky_bounce_sum(float *kernel, bool sun, uint32_t bounces, double *added)
{
    enum { MOST = SB_PROBE_SH + SB_SUN_DIRECTIONS, S = SB_BOUNCE_SH };
    const int K = sun ? MOST : SB_PROBE_SH;
    double total[S][MOST][3], term[S][MOST][3], next[S][MOST][3], op[S][S][3];
    double first = 0, peak = 0;
    for (int m = 0; m < S; m++) {
        for (int k = 0; k < K; k++)
            for (int c = 0; c < 3; c++) {
                total[m][k][c] = term[m][k][c] = kernel[column_at(m, k, c)];
                peak = fmax(peak, fabs(term[m][k][c]));
            }
        for (int j = 0; j < S; j++)
            for (int c = 0; c < 3; c++)
                op[m][j][c] = kernel[SB_BOUNCE_FLOATS + (m * S + j) * 3 + c];
    }
    for (int c = 0; c < 3; c++) /* the light the first bounce sends: the sky's constant band, or the sun's */
        for (int k = sun ? SB_PROBE_SH : 0; k < (sun ? K : 1); k++)
            first += total[0][k][c];
    if (peak == 0) { /* nothing to bounce */
        if (added)
            *added = 0;
        return 0;
    }
    /* every bounce: (I - M)^-1 B1, where the series surely converges */
    bool closed = !bounces;
    for (int c = 0; c < 3 && closed; c++) {
        double m[S][S], g[S][S];
        for (int i = 0; i < S; i++)
            for (int j = 0; j < S; j++)
                m[i][j] = op[i][j][c];
        if ((closed = every_bounce(m, g)))
            for (int i = 0; i < S; i++)
                for (int k = 0; k < K; k++) {
                    double v = 0;
                    for (int j = 0; j < S; j++)
                        v += g[i][j] * term[j][k][c];
                    next[i][k][c] = v;
                }
    }
    if (closed) {
        memcpy(total, next, sizeof(total));
        peak = 0; /* no series to sum */
    }
    uint32_t most = bounces ? bounces : SB_SKY_BOUNCE_MAX, n = closed ? 0 : 1;
    /* the next bounce is M times the last, channel by channel */
    for (; n < most && peak > 0; n++) {
        double size = 0;
        for (int m = 0; m < S; m++)
            for (int k = 0; k < K; k++)
                for (int c = 0; c < 3; c++) {
                    double v = 0;
                    for (int j = 0; j < S; j++)
                        v += op[m][j][c] * term[j][k][c];
                    next[m][k][c] = v;
                    size = fmax(size, fabs(v));
                }
        memcpy(term, next, sizeof(term));
        peak = 0;
        for (int m = 0; m < S; m++)
            for (int k = 0; k < K; k++)
                for (int c = 0; c < 3; c++) {
                    total[m][k][c] += term[m][k][c];
                    peak = fmax(peak, fabs(total[m][k][c]));
                }
        if (!bounces && size < SB_SKY_BOUNCE_CONVERGED * peak) {
            n++;
            break;
        }
    }
    double all = 0;
    for (int m = 0; m < S; m++)
        for (int k = 0; k < K; k++)
            for (int c = 0; c < 3; c++)
                kernel[column_at(m, k, c)] = (float)total[m][k][c];
    for (int c = 0; c < 3; c++)
        for (int k = sun ? SB_PROBE_SH : 0; k < (sun ? K : 1); k++)
            all += total[0][k][c];
    if (added)
        *added = first > 0 ? all / first - 1.0 : 0.0;
    return n;
}

/* The bounces summed a probe at a time on every core (each probe's own:
 * the same whatever the thread count). */
struct sum_job {
    float *kernel, *out;
    bool sun;
    uint32_t bounces, stride, *terms;
    double *added;
};

void sb_sky_bounce_sun_table(const float *kernel, float table[SB_BOUNCE_SUN_TABLE])
{
    const float *sun = kernel + SB_BOUNCE_KERNEL_FLOATS;
    double shape[SB_BOUNCE_SH * 3] = {0}, sum = 0;
    for (int j = 0; j < SB_SUN_DIRECTIONS; j++) {
        const float *b = &sun[j * SB_BOUNCE_SH * 3];
        double grey = ((double)b[0] + b[1] + b[2]) / 3;
        table[j] = (float)fmin(fmax(grey, -SB_SKY_BOUNCE_LIMIT), SB_SKY_BOUNCE_LIMIT);
        sum += grey;
        for (int mc = 0; mc < SB_BOUNCE_SH * 3; mc++)
            shape[mc] += b[mc];
    }
    for (int mc = 0; mc < SB_BOUNCE_SH * 3; mc++) {
        double v = sum > 0 ? shape[mc] / sum : 0.0;
        table[SB_SUN_DIRECTIONS + mc] = (float)fmin(fmax(v, -SB_SKY_BOUNCE_LIMIT), SB_SKY_BOUNCE_LIMIT);
    }
}

static void sum_one(void *user, int i)
{
    struct sum_job *job = user;
    float *k = &job->kernel[(size_t)i * job->stride];
    job->terms[i] = sb_sky_bounce_sum(k, job->sun, job->bounces, &job->added[i]);
    if (job->sun)
        sb_sky_bounce_sun_table(k, &job->out[(size_t)i * SB_BOUNCE_SUN_TABLE]);
    else
        memcpy(&job->out[(size_t)i * SB_BOUNCE_FLOATS], k, SB_BOUNCE_FLOATS * sizeof(float));
}

enum sb_result sb_sky_bounce_bake(struct sb_raycaster *rc, const struct sb_surfaces *surfaces, const float *positions,
                                  const float *valid, uint32_t probe_count, const struct sb_sky_bounce_params *params,
                                  float *out, double *gpu_ms, struct sb_sky_bounce_report *report)
{
    static const struct sb_sky_bounce_params defaults = {0};
    params = params ? params : &defaults;
    bool sun = params->sun;
    struct sb_bounce_push pc = {
        .probe_count = probe_count,
        .ray_count = params->ray_count ? params->ray_count : sun ? 1024 : 256,
        .secondary = sun ? 0 : params->secondary ? params->secondary : 64,
        .tmin_m = params->tmin_m > 0 ? params->tmin_m : 1e-4f,
        .tmax_m = params->tmax_m > 0 ? params->tmax_m : 1e30f,
        .stride = sun ? SB_BOUNCE_SUN_KERNEL_FLOATS : SB_BOUNCE_KERNEL_FLOATS,
    };
    if (gpu_ms)
        *gpu_ms = 0;
    if (report)
        *report = (struct sb_sky_bounce_report){0};
    if (pc.ray_count % SB_PROBE_THREADS || pc.ray_count > SB_PROBE_MAX_RAYS || pc.secondary > SB_PROBE_MAX_RAYS / 2 ||
        !probe_count || !surfaces->material_count || params->bounces > SB_SKY_BOUNCE_MAX) {
        sb_error("%s bounce: %u rays and %u from each hit for %u probes, %u bounces (rays: a multiple of %u up to "
                 "%u; bounces up to %u)",
                 sun ? "sun" : "sky", pc.ray_count, pc.secondary, probe_count, params->bounces, SB_PROBE_THREADS,
                 SB_PROBE_MAX_RAYS, SB_SKY_BOUNCE_MAX);
        return SB_ERR_OUT_OF_RANGE;
    }
    struct sb_vk *vk = rc->vk;
    struct sb_buffer probes = {0}, results = {0};
    struct sb_pipeline pipeline = {0};
    const struct sb_pipeline_params pp = sb_sky_bounce_kernel(rc->instanced, sun);
    /* the kernel's output a chunk of probes at a time */
    uint32_t chunk = (uint32_t)(SB_SKY_BOUNCE_CHUNK_BYTES / (pc.stride * sizeof(float)));
    chunk = probe_count < chunk ? probe_count : chunk;
    float *kernel = malloc((size_t)chunk * pc.stride * sizeof(float));
    uint32_t *terms = malloc(probe_count * sizeof(uint32_t));
    double *added = malloc(probe_count * sizeof(double)), summing = 0;
    struct sum_job job = {.kernel = kernel, .sun = sun, .bounces = params->bounces, .stride = pc.stride};
    enum sb_result res = kernel && terms && added ? SB_OK : SB_ERR_NOMEM;
    if (res || (res = sb_pipeline_create(vk, &pp, &pipeline)))
        goto done;
    uint32_t sphere = 2 * pc.secondary;
    struct sb_probe_work work;
    sb_probe_work_begin(&work, sun ? "sun_bounce: probes' rays" : "sky_bounce: probes' rays",
                        pc.ray_count / SB_PROBE_THREADS *
                            ((sphere + SB_BOUNCE_PASS_DIRECTIONS - 1) / SB_BOUNCE_PASS_DIRECTIONS +
                             (sun ? (SB_SUN_DIRECTIONS + SB_BOUNCE_SUN_PASS - 1) / SB_BOUNCE_SUN_PASS : 0)),
                        probe_count);
    for (uint32_t start = 0; start < probe_count && !res; start += chunk) {
        uint32_t n = probe_count - start < chunk ? probe_count - start : chunk;
        if ((res = sb_probe_buffers_create(vk, positions + 3 * (size_t)start, valid ? valid + start : NULL, n,
                                           pc.stride, &probes, &results)))
            break;
        const struct sb_buffer *bindings[SB_BOUNCE_BINDING_COUNT] = {
            [SB_RAYCAST_BINDING_NODES] = &rc->nodes,
            [SB_RAYCAST_BINDING_TRIANGLES] = &rc->triangles,
            [SB_RAYCAST_BINDING_RAYS] = &probes,
            [SB_RAYCAST_BINDING_HITS] = &results,
        };
        sb_surfaces_bindings(surfaces, &bindings[SB_BOUNCE_BINDING_SURFACE]);
        sb_pipeline_bind(vk, &pipeline, bindings);
        /* the passes (config.h, SB_BOUNCE_PASS_DIRECTIONS), in a fixed
         * order: the sphere set's slices, or a sun run's directions */
        pc.probe_count = n;
        for (uint32_t ray = 0; ray < pc.ray_count && !res; ray += SB_PROBE_THREADS) {
            pc.first_ray = ray;
            for (uint32_t dir = 0; dir < sphere && !res; dir += SB_BOUNCE_PASS_DIRECTIONS) {
                pc.first_direction = dir;
                pc.accumulate = ray > 0 || dir > 0;
                res = sb_probe_kernel_pass(vk, &pipeline, &pc, n, &work, gpu_ms);
            }
            for (uint32_t dir = 0; sun && dir < SB_SUN_DIRECTIONS && !res; dir += SB_BOUNCE_SUN_PASS) {
                pc.first_direction = dir; /* each pass its own directions, B and M in the first */
                pc.accumulate = ray > 0;
                res = sb_probe_kernel_pass(vk, &pipeline, &pc, n, &work, gpu_ms);
            }
        }
        if (!res)
            res = sb_buffer_read(vk, &results, kernel);
        sb_buffer_destroy(vk, &results);
        sb_buffer_destroy(vk, &probes);
        if (res)
            break;
        double t0 = sb_now_s();
        job.out = out + (size_t)start * (sun ? SB_BOUNCE_SUN_TABLE : SB_BOUNCE_FLOATS);
        job.terms = terms + start;
        job.added = added + start;
        sb_parallel_for((int)n, sum_one, &job);
        summing += sb_now_s() - t0;
    }
    if (res)
        goto done;
    uint32_t counted = 0;
    double sum = 0; /* in probe order: the same sum whatever the threads */
    for (uint32_t i = 0; i < probe_count && report; i++) {
        if (valid && valid[i] == 0)
            continue;
        report->most_bounces = terms[i] > report->most_bounces ? terms[i] : report->most_bounces;
        report->most_added = fmax(report->most_added, added[i]);
        sum += added[i];
        counted++;
    }
    if (report && counted)
        report->mean_added = sum / counted;
    sb_debug("%s bounce: %u probes' bounces summed in %.1f ms", sun ? "sun" : "sky", probe_count, 1e3 * summing);
done:
    free(terms);
    free(added);
    free(kernel);
    sb_pipeline_destroy(vk, &pipeline);
    sb_buffer_destroy(vk, &results);
    sb_buffer_destroy(vk, &probes);
    return res;
}

void sb_sky_bounce_code_hash(bool sun, char out[33])
{
    char both[2 * 33];
    if (sun)
        sb_kernel_code_hash(sb_spv_probe_bounce_sun, sizeof(sb_spv_probe_bounce_sun), sb_spv_probe_bounce_sun_instanced,
                            sizeof(sb_spv_probe_bounce_sun_instanced), both);
    else
        sb_kernel_code_hash(sb_spv_probe_bounce, sizeof(sb_spv_probe_bounce), sb_spv_probe_bounce_instanced,
                            sizeof(sb_spv_probe_bounce_instanced), both);
    sb_surfaces_code_hash(both + 32);
    sb_hash_bytes(both, 64, out);
}
