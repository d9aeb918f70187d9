#include "probe_detail.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "level.h"
#include "log.h"
#include "parallel.h"

#define BRICK SB_PROBES_BRICK
/* Surfaces a ray down a lattice column counts at most: the lowest found
 * bounds the column's detail from below. */
#define MAX_SURFACES 32
/* Rays a cast, at most. */
#define RAYS_A_CAST (1u << 20)
/* How far under a surface the next ray down starts (m). */
#define BELOW_SURFACE_M 1e-3f

/* Where the lattice is: its first probe, its columns along x and z (a
 * multiple of BRICK) and its rows, from x z bounds and the world's y. */
struct lattice {
    double origin[3], spacing;
    int64_t columns[2]; /* x, z */
    int64_t rows;
};

static void lattice_over(const float lo[3], const float hi[3], double spacing, struct lattice *l)
{
    l->spacing = spacing;
    /* a step of margin each side, half a step off the multiples of the
     * spacing: walls and floors on round coordinates then fall between
     * probes, not on them (and bakes of moved worlds share their lattice
     * where they overlap) */
    for (int k = 0; k < 3; k++)
        l->origin[k] = spacing * (floor((double)lo[k] / spacing) - 0.5);
    for (int a = 0; a < 2; a++) {
        int k = a ? 2 : 0;
        int64_t n = (int64_t)ceil(((double)hi[k] - l->origin[k]) / spacing) + 2;
        l->columns[a] = (n + BRICK - 1) / BRICK * BRICK;
    }
    l->rows = (int64_t)ceil(((double)hi[1] - l->origin[1]) / spacing) + 2;
}

static enum sb_result lattice_check(const struct lattice *l, double spacing)
{
    int64_t most = l->columns[0] > l->columns[1] ? l->columns[0] : l->columns[1];
    if (l->rows > most)
        most = l->rows;
    if (most > SB_PROBES_MAX_LATTICE) {
        sb_error("probes: detail %g m apart takes %lld lattice steps across the world; at most %d: raise "
                 "probes.detail_spacing_m or bound it with probes.detail_volumes",
                 spacing, (long long)most, SB_PROBES_MAX_LATTICE);
        return SB_ERR_TOO_LARGE;
    }
    return SB_OK;
}

/* The box the lattice covers: what stands on the ground (the grid's
 * bounds) and every volume that forces detail; y: `ylo` to `yhi`. */
static bool detail_bounds(const struct sb_level *level, const struct sb_probe_params *p, float lo[3], float hi[3])
{
    bool any = sb_level_bounds_casting(level, lo, hi);
    for (int i = 0; i < p->detail_volume_count; i++) {
        const struct sb_probe_volume *v = &p->detail_volumes[i];
        if (!v->detail)
            continue;
        for (int k = 0; k < 3; k++) {
            lo[k] = any ? fminf(lo[k], (float)v->min_m[k]) : (float)v->min_m[k];
            hi[k] = any ? fmaxf(hi[k], (float)v->max_m[k]) : (float)v->max_m[k];
        }
        any = true;
    }
    return any;
}

enum sb_result sb_probe_detail_check(const struct sb_level *level, const struct sb_probe_params *params, double spacing)
{
    float lo[3], hi[3];
    if (!detail_bounds(level, params, lo, hi))
        return SB_OK;
    struct lattice l;
    lattice_over(lo, hi, spacing, &l);
    return lattice_check(&l, spacing);
}

/* Column flags: the last surface met was a front face; the column holds
 * a covered gap. */
#define FRONT 1u
#define COVERED 2u

/*
 * Each lattice column's surfaces: rays straight down from over the world,
 * each starting again just under the surface the last one met, until one
 * meets nothing. count[c] surfaces, the highest at top[c], the lowest at
 * low[c]; flags[c] COVERED where the column holds a covered gap: open
 * space at least `gap` high between two surfaces (not the inside of a
 * solid, entered through a front face and left through a back face).
 */
/* A chunk of the columns' rays, built and read in blocks on every core
 * (each block its own rays and columns: the same whatever the threads). */
struct column_job {
    const struct lattice *l;
    const uint32_t *which; /* the chunk's columns */
    uint32_t count;
    int round;
    float start_y;
    double gap;
    uint8_t *counts, *flags;
    float *top, *low, *rays, *hits;
};
#define COLUMN_BLOCK 16384

static void build_block(void *user, int block)
{
    struct column_job *job = user;
    uint32_t end = (uint32_t)block * COLUMN_BLOCK + COLUMN_BLOCK;
    end = end < job->count ? end : job->count;
    for (uint32_t i = (uint32_t)block * COLUMN_BLOCK; i < end; i++) {
        uint32_t c = job->which[i];
        uint64_t x = c % (uint64_t)job->l->columns[0], z = c / (uint64_t)job->l->columns[0];
        float *r = &job->rays[8 * (size_t)i];
        r[0] = (float)(job->l->origin[0] + (double)x * job->l->spacing);
        r[1] = job->round ? job->low[c] - BELOW_SURFACE_M : job->start_y;
        r[2] = (float)(job->l->origin[2] + (double)z * job->l->spacing);
        r[3] = 0.0f;
        r[4] = 0.0f;
        r[5] = -1.0f;
        r[6] = 0.0f;
        r[7] = 1e30f;
    }
}

static void read_block(void *user, int block)
{
    struct column_job *job = user;
    uint32_t end = (uint32_t)block * COLUMN_BLOCK + COLUMN_BLOCK;
    end = end < job->count ? end : job->count;
    for (uint32_t i = (uint32_t)block * COLUMN_BLOCK; i < end; i++) {
        uint32_t triangle;
        memcpy(&triangle, &job->hits[4 * (size_t)i + 1], sizeof(triangle));
        if (triangle == SB_BVH_MISS)
            continue;
        uint32_t c = job->which[i];
        float y = job->rays[8 * (size_t)i + 1] - job->hits[4 * (size_t)i];
        bool front = !(triangle & SB_BVH_BACK_FACE);
        uint8_t f = job->flags[c];
        if (!job->counts[c])
            job->top[c] = y;
        else if (!((f & FRONT) && !front) && (double)job->low[c] - y >= job->gap)
            f |= COVERED;
        job->flags[c] = (uint8_t)((f & ~FRONT) | (front ? FRONT : 0));
        job->low[c] = y;
        job->counts[c]++;
    }
}

static enum sb_result column_surfaces(struct sb_raycaster *rc, const struct lattice *l, float start_y, double gap,
                                      uint8_t *count, uint8_t *flags, float *top, float *low, double *gpu_ms)
{
    uint64_t n = (uint64_t)l->columns[0] * (uint64_t)l->columns[1];
    uint32_t chunk = n < RAYS_A_CAST ? (uint32_t)n : RAYS_A_CAST;
    float *rays = malloc((size_t)chunk * 8 * sizeof(float)), *hits = malloc((size_t)chunk * 4 * sizeof(float));
    uint32_t *which = malloc((size_t)n * sizeof(uint32_t));
    enum sb_result res = rays && hits && which ? SB_OK : SB_ERR_NOMEM;
    /* an active column's next ray starts at low[c] (start_y before any hit) */
    for (uint64_t c = 0; c < n; c++) {
        count[c] = flags[c] = 0;
        low[c] = top[c] = start_y;
    }
    struct column_job job = {.l = l, .start_y = start_y, .gap = gap, .counts = count, .flags = flags, .top = top,
                             .low = low, .rays = rays, .hits = hits};
    for (int round = 0; round < MAX_SURFACES && !res; round++) {
        /* the columns still going (met something on each ray so far), in order */
        uint32_t active = 0;
        for (uint64_t c = 0; c < n; c++)
            if (count[c] == round)
                which[active++] = (uint32_t)c;
        if (!active)
            break;
        job.round = round;
        for (uint32_t first = 0; first < active && !res; first += chunk) {
            job.which = &which[first];
            job.count = active - first < chunk ? active - first : chunk;
            int blocks = (int)((job.count + COLUMN_BLOCK - 1) / COLUMN_BLOCK);
            sb_parallel_for(blocks, build_block, &job);
            double ms = 0;
            if ((res = sb_raycaster_cast(rc, rays, job.count, false, hits, &ms)))
                break;
            *gpu_ms += ms;
            sb_parallel_for(blocks, read_block, &job);
        }
    }
    free(rays);
    free(hits);
    free(which);
    return res;
}

/* A cap passed: an error, or (under a budget, which coarsens) a note. */
#define over_cap(budget, ...) sb_log((budget) ? SB_LOG_DEBUG : SB_LOG_ERROR, __VA_ARGS__)

enum sb_result sb_probe_detail_place(struct sb_raycaster *rc, const struct sb_bvh *bvh, const struct sb_level *level,
                                     const struct sb_probe_params *p, double spacing, bool budget,
                                     struct sb_probe_layout *layout)
{
    layout->columns = NULL;
    layout->column_count = layout->detail_count = 0;
    float lo[3], hi[3];
    if (!detail_bounds(level, p, lo, hi) || !bvh->node_count)
        return SB_OK;
    /* the lattice's rows from under the world's lowest point to over its highest */
    const struct sb_bvh_node *root = &bvh->nodes[0];
    lo[1] = fminf(lo[1], root->min[1]);
    hi[1] = fmaxf(hi[1], root->max[1]);
    struct lattice l;
    lattice_over(lo, hi, spacing, &l);
    enum sb_result res = lattice_check(&l, spacing);
    if (res)
        return res;
    uint64_t n = (uint64_t)l.columns[0] * (uint64_t)l.columns[1];
    int64_t bx_count = l.columns[0] / BRICK, bz_count = l.columns[1] / BRICK;
    uint64_t bricks = (uint64_t)bx_count * (uint64_t)bz_count;
    uint8_t *count = malloc(n), *flags = malloc(n);
    float *top = malloc(n * sizeof(float)), *low = malloc(n * sizeof(float));
    float *brick_lo = malloc(bricks * sizeof(float)), *brick_hi = malloc(bricks * sizeof(float));
    if (!count || !flags || !top || !low || !brick_lo || !brick_hi) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    double gpu_ms = 0, t0 = sb_now_s();
    /* a gap thinner than the scene's detail spacing holds no row of its
     * own (under a car, a solid box on the ground): the grid's probes
     * light it as they light the ground around */
    if ((res = column_surfaces(rc, &l, root->max[1] + 1.0f, p->detail_spacing_m, count, flags, top, low, &gpu_ms)))
        goto done;
    /* a column that holds a covered gap makes detail over its range in
     * its brick column and those of its 8 neighbours' */
    for (uint64_t b = 0; b < bricks; b++) {
        brick_lo[b] = INFINITY;
        brick_hi[b] = -INFINITY;
    }
    uint64_t multiple = 0;
    for (uint64_t c = 0; c < n; c++) {
        if (!(flags[c] & COVERED))
            continue;
        multiple++;
        int64_t x = (int64_t)(c % (uint64_t)l.columns[0]), z = (int64_t)(c / (uint64_t)l.columns[0]);
        for (int dz = -1; dz <= 1; dz++)
            for (int dx = -1; dx <= 1; dx++) {
                int64_t nx = x + dx, nz = z + dz;
                if (nx < 0 || nz < 0 || nx >= l.columns[0] || nz >= l.columns[1])
                    continue;
                uint64_t b = (uint64_t)(nz / BRICK) * (uint64_t)bx_count + (uint64_t)(nx / BRICK);
                brick_lo[b] = fminf(brick_lo[b], low[c]);
                brick_hi[b] = fmaxf(brick_hi[b], top[c]);
            }
    }
    /* the scene's volumes, in order: a brick column whose centre a volume
     * holds (in x and z) gains its heights (detail true), or loses the
     * part of its range the volume holds (false; a volume strictly inside
     * the range leaves it whole) */
    for (int i = 0; i < p->detail_volume_count; i++) {
        const struct sb_probe_volume *v = &p->detail_volumes[i];
        for (uint64_t b = 0; b < bricks; b++) {
            double cx = l.origin[0] + ((double)(b % (uint64_t)bx_count) * BRICK + 0.5 * (BRICK - 1)) * spacing;
            double cz = l.origin[2] + ((double)(b / (uint64_t)bx_count) * BRICK + 0.5 * (BRICK - 1)) * spacing;
            if (cx < v->min_m[0] || cx > v->max_m[0] || cz < v->min_m[2] || cz > v->max_m[2])
                continue;
            if (v->detail) {
                brick_lo[b] = fminf(brick_lo[b], (float)v->min_m[1]);
                brick_hi[b] = fmaxf(brick_hi[b], (float)v->max_m[1]);
            } else if (brick_lo[b] >= v->min_m[1] && brick_hi[b] <= v->max_m[1]) {
                brick_lo[b] = INFINITY;
                brick_hi[b] = -INFINITY;
            } else if (brick_lo[b] >= v->min_m[1] && brick_lo[b] <= v->max_m[1]) {
                brick_lo[b] = (float)v->max_m[1];
            } else if (brick_hi[b] >= v->min_m[1] && brick_hi[b] <= v->max_m[1]) {
                brick_hi[b] = (float)v->min_m[1];
            }
        }
    }
    uint64_t columns = 0;
    for (uint64_t b = 0; b < bricks; b++)
        columns += brick_lo[b] <= brick_hi[b];
    if (columns > SB_PROBES_MAX_COLUMNS) {
        over_cap(budget, "probes: detail %g m apart takes %llu brick columns; at most %u: raise probes.detail_spacing_m, "
                 "set probes.budget_mb, or forbid detail where it is not needed (probes.detail_volumes)",
                 spacing, (unsigned long long)columns, SB_PROBES_MAX_COLUMNS);
        res = SB_ERR_TOO_LARGE;
        goto done;
    }
    layout->columns = columns ? malloc(columns * sizeof(*layout->columns)) : NULL;
    if (columns && !layout->columns) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    /* rows from the lattice row at or under the lowest surface (points on
     * it have probes around them) to one over the highest */
    uint64_t probes = 0;
    for (uint64_t b = 0; b < bricks; b++) {
        if (!(brick_lo[b] <= brick_hi[b]))
            continue;
        int64_t y0 = (int64_t)floor((brick_lo[b] - l.origin[1]) / spacing);
        int64_t y1 = (int64_t)ceil((brick_hi[b] - l.origin[1]) / spacing) + 1;
        y0 = y0 < 0 ? 0 : y0;
        y1 = y1 < y0 ? y0 : y1 >= SB_PROBES_MAX_LATTICE ? SB_PROBES_MAX_LATTICE - 1 : y1;
        layout->columns[layout->column_count++] = (struct sb_probe_column){
            .x = (int32_t)(b % (uint64_t)bx_count),
            .z = (int32_t)(b / (uint64_t)bx_count),
            .y0 = (int32_t)y0,
            .rows = (uint32_t)(y1 - y0 + 1),
        };
        probes += (uint64_t)(y1 - y0 + 1) * BRICK * BRICK;
    }
    if (probes > SB_PROBES_MAX_COUNT) {
        over_cap(budget, "probes: detail %g m apart takes %llu probes; at most %u: raise probes.detail_spacing_m, set "
                 "probes.budget_mb, or forbid detail where it is not needed (probes.detail_volumes)",
                 spacing, (unsigned long long)probes, SB_PROBES_MAX_COUNT);
        res = SB_ERR_TOO_LARGE;
        goto done;
    }
    layout->detail_count = (uint32_t)probes;
    layout->detail_spacing_m = (float)spacing;
    for (int k = 0; k < 3; k++)
        layout->detail_origin_m[k] = (float)l.origin[k];
    sb_debug("probes: detail %g m apart: %llu lattice columns cast down (%.1f ms, %.3f ms on the device), %llu over "
             "a covered gap; %u brick columns, %u probes",
             spacing, (unsigned long long)n, 1e3 * (sb_now_s() - t0), gpu_ms, (unsigned long long)multiple,
             layout->column_count, layout->detail_count);
done:
    if (res) {
        free(layout->columns);
        layout->columns = NULL;
        layout->column_count = layout->detail_count = 0;
    }
    free(count);
    free(flags);
    free(top);
    free(low);
    free(brick_lo);
    free(brick_hi);
    return res;
}

void sb_probe_detail_positions(const struct sb_probe_layout *layout, float *positions)
{
    const double s = layout->detail_spacing_m;
    size_t i = 0;
    for (uint32_t c = 0; c < layout->column_count; c++) {
        const struct sb_probe_column *col = &layout->columns[c];
        for (uint32_t y = 0; y < col->rows; y++)
            for (int k = 0; k < BRICK; k++)
                for (int j = 0; j < BRICK; j++, i++) {
                    positions[3 * i] = (float)(layout->detail_origin_m[0] + (double)(col->x * BRICK + j) * s);
                    positions[3 * i + 1] = (float)(layout->detail_origin_m[1] + (double)(col->y0 + (int32_t)y) * s);
                    positions[3 * i + 2] = (float)(layout->detail_origin_m[2] + (double)(col->z * BRICK + k) * s);
                }
    }
}
