/*
 * The probe family: sky visibility at probes over the scene's world
 * (family.h). A bake reads the world's mesh (geometry/mesh.h), builds its
 * BVH, places probes (a grid over the world's bounds, then the scene's
 * explicit ones), bakes them (sky_visibility.h), pushes the probes found
 * inside geometry out to free space where it can (recording the offset)
 * and flags the rest invalid, and derings every probe's SH.
 *
 * The key holds the world as read (its mesh's hash), the probe settings
 * and the kernel: the atmosphere does not rebake probes; a vertex does,
 * wherever it lives (a glTF's .bin, a linked file).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include "bake.h"
#include "bvh.h"
#include "family.h"
#include "json.h"
#include "level.h"
#include "load.h"
#include "log.h"
#include "mesh.h"
#include "parallel.h"
#include "probe_detail.h"
#include "probe_sight.h"
#include "probe_tiles.h"
#include "skybake_version.h"
#include "raycast.h"
#include "sh.h"
#include "sky_bounce.h"
#include "sky_visibility.h"

/* Candidate offsets for a probe inside geometry: the 26 neighbour
 * directions at these fractions of the spacing (or of 1 m without a grid),
 * tried in a fixed order with PUSH_RAYS rays each. */
static const double push_steps[] = {0.25, 0.5};
/* The detail's: its lattice stands half a step off round coordinates,
 * where floors and walls often are, and a quarter or half step would put
 * a pushed probe onto one (a probe on a floor sees through it). */
static const double detail_push_steps[] = {0.3, 0.6};
_Static_assert(sizeof(push_steps) == sizeof(detail_push_steps), "as many candidates a probe");
#define PUSH_RAYS 256
#define PROBES_RECIPE 3 /* 2: rays cast in sb_probe_ray_order; 3: the exact deringing window */

/* The world as read for this bake: the key's input and the bake's; its
 * BVH on the device, built by the first product baked. */
struct probes_state {
    const struct sb_level *level;
    char mesh_hash[SB_HASH_HEX_SIZE];
    char path[640]; /* the world's file, absolute */
    struct sb_bvh bvh;
    struct sb_raycaster *rc;
    struct sb_surfaces surfaces; /* the bounce's, made with rc */
    /* the detail's brick columns, placed by the first bake that needs them */
    struct sb_probe_layout detail;
    bool detail_placed;
    /* tiles: what the level places where (made by the first bake), and
     * each product as the pack there before held it (probes_previous) */
    struct sb_level_regions regions;
    bool regions_made;
    struct previous {
        struct sb_probe_layout layout;
        struct sb_image image;
    } prev[3][SB_BAKE_MAX_SOURCES]; /* sky_visibility, sky_bounce, sun_bounce: the pack there, then --from packs */
    uint32_t prev_count[3];
};

/* The probe products' index in probes_state's arrays. */
static int slot(enum sb_product_id id)
{
    return id == SB_PRODUCT_SKY_BOUNCE ? 1 : id == SB_PRODUCT_SUN_BOUNCE ? 2 : 0;
}

/* The two bounce products, made by one kernel. */
static bool is_bounce(enum sb_product_id id)
{
    return id == SB_PRODUCT_SKY_BOUNCE || id == SB_PRODUCT_SUN_BOUNCE;
}

static enum sb_result plan(const struct sb_scene *scene, const struct sb_level *level, bool say,
                           struct sb_probe_layout *layout, uint64_t *grid_out);

static enum sb_result probes_create(struct sb_vk *vk, const struct sb_scene *scene, void **out)
{
    struct probes_state *st = calloc(1, sizeof(*st));
    if (!st)
        return SB_ERR_NOMEM;
    enum sb_result res = sb_level_acquire(&scene->world, scene->directory, &st->level, st->path, sizeof(st->path));
    struct sb_probe_layout layout = {0};
    uint64_t grid;
    if (!res)
        res = plan(scene, st->level, true, &layout, &grid);
    if (res) {
        sb_level_release(&st->level);
        free(st);
        return res;
    }
    sb_level_hash(st->level, st->mesh_hash);
    *out = st;
    return SB_OK;
}

static void probes_destroy(void **state)
{
    struct probes_state *st = *state;
    if (st) {
        if (st->rc)
            sb_surfaces_destroy(st->rc->vk, &st->surfaces);
        sb_raycaster_destroy(&st->rc);
        sb_bvh_finish(&st->bvh);
        sb_probe_layout_finish(&st->detail);
        sb_level_regions_finish(&st->regions);
        for (int i = 0; i < 3; i++)
            for (uint32_t k = 0; k < st->prev_count[i]; k++) {
                sb_probe_layout_finish(&st->prev[i][k].layout);
                sb_image_finish(&st->prev[i][k].image);
            }
        sb_level_release(&st->level);
    }
    free(st);
    *state = NULL;
}

/* How far the probes' rays reach (0: unlimited): the scene's, else a
 * quarter of its tiles. */
static double reach_of(const struct sb_probe_params *p)
{
    return p->reach_m > 0 ? p->reach_m : p->tile_m > 0 ? p->tile_m / 4 : 0;
}

/* What a probe product depends on but the world: the probe settings and
 * the kernels (a tile's key adds what of the world its probes see). */
static void key_settings(const struct sb_scene *scene, enum sb_product_id id, struct sb_key_text *key)
{
    const struct sb_probe_params *p = &scene->probes;
    char code[SB_HASH_HEX_SIZE];
    sb_key_add(key, " spacing_m=%a margin_m=%a rays=%u inside=%a", p->spacing_m, p->margin_m, p->rays,
               p->inside_fraction);
    if (p->has_bounds) {
        sb_key_add3(key, "bounds_min", p->bounds_m[0]);
        sb_key_add3(key, "bounds_max", p->bounds_m[1]);
    }
    for (int i = 0; i < p->explicit_count; i++)
        sb_key_add3(key, "at", p->positions_m[i]);
    for (int l = 0; l < p->layer_count; l++) /* none: the keys of uniform grids as they were */
        sb_key_add(key, " layer=%a", p->layers_m[l]);
    if (p->budget_mb > 0)
        sb_key_add(key, " budget_mb=%a", p->budget_mb);
    if (p->detail_spacing_m > 0) { /* none: the keys as they were */
        sb_key_add(key, " detail_spacing_m=%a", p->detail_spacing_m);
        for (int i = 0; i < p->detail_volume_count; i++) {
            sb_key_add3(key, p->detail_volumes[i].detail ? "force_min" : "forbid_min", p->detail_volumes[i].min_m);
            sb_key_add3(key, p->detail_volumes[i].detail ? "force_max" : "forbid_max", p->detail_volumes[i].max_m);
        }
    }
    if (p->tile_m > 0 || p->reach_m > 0) /* likewise */
        sb_key_add(key, " tile_m=%a reach_m=%a", p->tile_m, reach_of(p));
    sb_sky_visibility_code_hash(code);
    sb_key_add(key, " code %s", code);
    if (p->detail_spacing_m > 0) { /* the detail's sight masks */
        sb_probe_sight_code_hash(code);
        sb_key_add(key, " sight_code %s", code);
    }
    if (id == SB_PRODUCT_SKY_BOUNCE) { /* and the visibility's key, as its input */
        sb_sky_bounce_code_hash(false, code);
        /* bounce_sum: the host's sum of the bounces (sky_bounce.c) */
        sb_key_add(key, " bounce_rays=%u secondary=%u bounces=%u bounce_sum 1 bounce_code %s", p->bounce_rays,
                   p->bounce_secondary, p->bounces, code);
    }
    if (id == SB_PRODUCT_SUN_BOUNCE) { /* sun_sum: the table's sum and shape (sky_bounce.c) */
        sb_sky_bounce_code_hash(true, code);
        sb_key_add(key, " sun_rays=%u bounces=%u sun_sum 1 sun_side %d bounce_code %s", p->sun_rays, p->bounces,
                   SB_SUN_SIDE, code);
    }
}

/* The world as it was read (every vertex, index, material and albedo after
 * the placement: a glTF's external buffers and a linked file included),
 * not the file's bytes; the probe settings; the kernel; the tiles a bake
 * of some tiles alone bakes. */
static void probes_key(void *state, const struct sb_scene *scene, enum sb_product_id id, struct sb_key_text *key)
{
    const struct probes_state *st = state;
    sb_key_add(key, " recipe %d world %s bvh %d", PROBES_RECIPE, st->mesh_hash, SB_BVH_VERSION);
    key_settings(scene, id, key);
    for (int i = 0; i < scene->probes.only_tile_count; i++)
        sb_key_add(key, " only_tile=%d,%d", scene->probes.only_tiles[i][0], scene->probes.only_tiles[i][1]);
}

static void probes_previous(void *state, enum sb_product_id id, struct sb_artifact *was, struct sb_image *image)
{
    struct probes_state *st = state;
    int i = slot(id);
    if (!was->probes.tile_count || st->prev_count[i] == SB_BAKE_MAX_SOURCES)
        return; /* nothing to keep but whole products (bake.c) */
    struct previous *to = &st->prev[i][st->prev_count[i]];
    if (sb_probe_layout_copy(&to->layout, &was->probes))
        return; /* out of memory: its tiles are cast */
    to->image = *image;
    *image = (struct sb_image){0};
    st->prev_count[i]++;
}

static uint32_t probes_depends_on(enum sb_product_id id)
{
    /* the sun's bounce relights with the sky's (a runtime reads both) */
    return id == SB_PRODUCT_SUN_BOUNCE ? 1u << SB_PRODUCT_SKY_VISIBILITY | 1u << SB_PRODUCT_SKY_BOUNCE
           : id == SB_PRODUCT_SKY_BOUNCE ? 1u << SB_PRODUCT_SKY_VISIBILITY
                                         : 0;
}

/* The level's BVH on the device; under tiles its wide instances flagged
 * (probe_tiles.h: what every tile sees at any distance). */
static enum sb_result raycaster(struct probes_state *st, const struct sb_scene *scene, struct sb_vk *vk)
{
    enum sb_result res = SB_OK;
    if (st->rc)
        return SB_OK;
    if (scene->probes.tile_m > 0 && !st->regions_made &&
        !(res = sb_level_regions_make(st->level, 2 * scene->probes.tile_m, &st->regions)))
        st->regions_made = true;
    if (!res)
        res = sb_level_build_bvh(st->level, &st->bvh);
    if (!res && st->regions_made)
        sb_level_regions_mark(&st->regions, &st->bvh);
    if (!res)
        res = sb_raycaster_create(vk, &st->bvh, &st->rc);
    return res;
}

/* The grid over the world's bounds (or the scene's), centred on them, and
 * its size checked against the caps: from the scene and its world alone,
 * so that probes_create refuses a grid before any product is baked. */
/* The bytes a probe takes in the pack: its sky_visibility record (fp32)
 * and, when the scene bakes them, its sky_bounce and sun_bounce records
 * (binary16). */
static uint64_t probe_bytes(const struct sb_scene *scene)
{
    return 4 * SB_SKY_VISIBILITY_CHANNEL_COUNT +
           (scene->wants[SB_PRODUCT_SKY_BOUNCE] ? 2 * SB_SKY_BOUNCE_CHANNEL_COUNT : 0) +
           (scene->wants[SB_PRODUCT_SUN_BOUNCE] ? 2 * SB_SUN_BOUNCE_CHANNEL_COUNT : 0);
}

/* The grid `spacing` apart over lo..hi (layers over the surface where the
 * scene has them) into layout; returns its probe count, or 0 when an axis
 * would pass SB_PROBES_MAX_GRID (*axis: which). */
static uint64_t grid_at(const struct sb_probe_params *p, const float lo[3], const float hi[3], double spacing,
                        struct sb_probe_layout *layout, int *axis)
{
    uint64_t grid = 1;
    for (int k = 0; k < 3; k++) {
        if (k == 1 && p->layer_count) {
            /* layers over the surface: the y origin 0, the y spacing
             * the distance over the top layer a runtime fades over */
            int n = p->layer_count;
            layout->grid[1] = (uint32_t)n;
            layout->origin_m[1] = 0;
            layout->spacing_m[1] = (float)(n > 1 ? p->layers_m[n - 1] - p->layers_m[n - 2] : p->layers_m[0]);
            layout->layer_count = (uint32_t)n;
            for (int l = 0; l < n; l++)
                layout->layers_m[l] = (float)p->layers_m[l];
            grid *= (uint64_t)n;
            continue;
        }
        double extent = (double)hi[k] - lo[k] + 2 * p->margin_m;
        double n = floor(extent / spacing) + 1, first = 0;
        if (p->tile_m > 0) { /* on multiples of the spacing: a grid that moves rebakes every tile */
            first = floor(((double)lo[k] - p->margin_m) / spacing);
            n = ceil(((double)hi[k] + p->margin_m) / spacing) - first + 1;
        }
        if (n > SB_PROBES_MAX_GRID) {
            *axis = k;
            return 0;
        }
        layout->grid[k] = (uint32_t)n;
        layout->spacing_m[k] = (float)spacing;
        layout->origin_m[k] = p->tile_m > 0 ? (float)(first * spacing)
                                            : (float)(0.5 * ((double)lo[k] + hi[k]) - 0.5 * (n - 1) * spacing);
        grid *= (uint64_t)n;
    }
    return grid;
}

/*
 * The grid over the world's casters (or the scene's bounds), spaced wider
 * than probes.spacing_m where the probes would take more than the scene's
 * budget (`say`: log that), and its size checked against the caps.
 */
static enum sb_result plan(const struct sb_scene *scene, const struct sb_level *level, bool say,
                           struct sb_probe_layout *layout, uint64_t *grid_out)
{
    const struct sb_probe_params *p = &scene->probes;
    uint64_t grid = 0;
    if (p->spacing_m > 0) {
        float lo[3], hi[3]; /* what stands on a ground, not the ground */
        sb_level_bounds_casting(level, lo, hi);
        for (int k = 0; k < 3 && p->has_bounds; k++) {
            lo[k] = (float)p->bounds_m[0][k];
            hi[k] = (float)p->bounds_m[1][k];
        }
        int axis = 0;
        double spacing = p->spacing_m, budget = p->budget_mb * 1e6, per = (double)probe_bytes(scene);
        grid = grid_at(p, lo, hi, spacing, layout, &axis);
        double want = (double)(grid + (uint64_t)p->explicit_count) * per;
        if (budget > 0 && (!grid || want > budget)) {
            /* wider by the count's root (2 axes under layers, 3 without),
             * then by 1% steps where the counts' rounding leaves it over */
            int axes = p->layer_count ? 2 : 3;
            double bytes = want;
            for (int step = 0; step < 1000 && (!grid || bytes > budget); step++) {
                double ratio = grid ? pow(bytes / budget, 1.0 / axes) : 2.0;
                spacing *= ratio > 1.01 ? ratio : 1.01;
                grid = grid_at(p, lo, hi, spacing, layout, &axis);
                bytes = (double)(grid + (uint64_t)p->explicit_count) * per;
            }
            if (grid && (double)p->explicit_count * per > budget)
                grid = 0; /* the explicit probes alone do not fit: refused below */
            if (grid && say)
                sb_warn("probes: %g m apart the probes would take %.3g MB, over probes.budget_mb (%g): %.3g m apart "
                        "instead, %llu probes, %.3g MB",
                        p->spacing_m, want / 1e6, p->budget_mb, spacing, (unsigned long long)(grid + p->explicit_count),
                        bytes / 1e6);
            if (!grid) {
                sb_error("probes: no grid fits probes.budget_mb (%g MB; %llu explicit probes take %.3f MB)",
                         p->budget_mb, (unsigned long long)p->explicit_count, p->explicit_count * per / 1e6);
                return SB_ERR_TOO_LARGE;
            }
        }
        if (!grid) {
            double extent = (double)hi[axis] - lo[axis];
            sb_error("probes: %.0f probes along %c (the %s %.1f m across with a %g m margin); at most %d: raise "
                     "probes.spacing_m%s%s",
                     floor((extent + 2 * p->margin_m) / spacing) + 1, "xyz"[axis],
                     p -> has_bounds ? "bounds are" : "world is", extent, p->margin_m, SB_PROBES_MAX_GRID,
                     p->has_bounds ? "" : " or give probes.bounds_m",
                     p->has_bounds ? "" : " (a model in millimetres or centimetres: set world.units_m)");
            return SB_ERR_TOO_LARGE;
        }
    }
    if (p->budget_mb > 0 && !grid && (double)p->explicit_count * (double)probe_bytes(scene) > p->budget_mb * 1e6) {
        sb_error("probes: %d explicit probes take %.3g MB, over probes.budget_mb (%g)", p->explicit_count,
                 p->explicit_count * (double)probe_bytes(scene) / 1e6, p->budget_mb);
        return SB_ERR_TOO_LARGE;
    }
    if (p->detail_spacing_m > 0) {
        enum sb_result res = sb_probe_detail_check(level, p, p->detail_spacing_m);
        if (res)
            return res;
    }
    if (grid + (uint64_t)p->explicit_count > SB_PROBES_MAX_COUNT) {
        /* a model in millimetres is the usual reason a world is this large */
        sb_error("probes: %llu probes (a grid of %u x %u x %u, %g m apart, over the %s); at most %u: raise "
                 "probes.spacing_m%s%s",
                 (unsigned long long)(grid + p->explicit_count), layout->grid[0], layout->grid[1], layout->grid[2],
                 (double)layout->spacing_m[0], p->has_bounds ? "bounds" : "world's shadow casters", SB_PROBES_MAX_COUNT,
                 p->has_bounds ? "" : ", give probes.bounds_m",
                 scene->has_world && !p->has_bounds
                     ? ", or, for a model in millimetres or centimetres, set world.units_m (0.001, 0.01)"
                     : "");
        return SB_ERR_TOO_LARGE;
    }
    *grid_out = grid;
    return SB_OK;
}

/* The surface under each column of a grid of layers: where a ray straight
 * down from over the world first meets it (the world's bottom where it
 * meets none), into ground[column] (x fastest). */
static enum sb_result column_surfaces(const struct probes_state *st, const struct sb_probe_layout *layout,
                                      float *ground)
{
    uint32_t columns = layout->grid[0] * layout->grid[2];
    float *rays = malloc((size_t)columns * 8 * sizeof(float)), *hits = malloc((size_t)columns * 4 * sizeof(float));
    enum sb_result res = rays && hits ? SB_OK : SB_ERR_NOMEM;
    const struct sb_bvh_node *root = &st->bvh.nodes[0];
    float top = root->max[1] + 1.0f;
    for (uint32_t c = 0; c < columns && !res; c++) {
        float *r = &rays[8 * (size_t)c];
        r[0] = layout->origin_m[0] + (float)(c % layout->grid[0]) * layout->spacing_m[0];
        r[1] = top;
        r[2] = layout->origin_m[2] + (float)(c / layout->grid[0]) * layout->spacing_m[2];
        r[3] = 0.0f;
        r[4] = 0.0f;
        r[5] = -1.0f;
        r[6] = 0.0f;
        r[7] = 1e30f;
    }
    double ms = 0;
    if (!res)
        res = sb_raycaster_cast(st->rc, rays, columns, false, hits, &ms);
    uint32_t missed = 0;
    for (uint32_t c = 0; c < columns && !res; c++) {
        uint32_t triangle;
        memcpy(&triangle, &hits[4 * (size_t)c + 1], sizeof(triangle));
        missed += triangle == SB_BVH_MISS;
        ground[c] = triangle == SB_BVH_MISS ? root->min[1] : top - hits[4 * (size_t)c];
    }
    if (!res)
        sb_debug("probes: %u columns' surfaces found (%.3f ms on the device), %u over nothing", columns, ms, missed);
    free(rays);
    free(hits);
    return res;
}

/* The detail's spacings a budget coarsens to: the scene's times 2^(k /
 * DETAIL_LEVELS), k >= 1. Levels rather than any spacing that fits keep
 * the spacing where it was when a house moves (the count moves a little;
 * the spacing, and with it every tile's key, stays unless the count
 * crosses a level), and the search short. */
#define DETAIL_LEVELS 16

static double detail_level(double spacing, int k)
{
    return spacing * exp2((double)k / DETAIL_LEVELS);
}

/*
 * The detail's brick columns (probe_detail.h), once a bake: at the scene's
 * spacing, else under a budget at the finest level (detail_level) whose
 * probes fit what the budget leaves after the grid's and the explicit
 * probes' `taken` bytes (none when nothing is left), saying so.
 */
static enum sb_result place_detail(struct probes_state *st, const struct sb_scene *scene, uint64_t taken)
{
    const struct sb_probe_params *p = &scene->probes;
    if (st->detail_placed || p->detail_spacing_m <= 0)
        return SB_OK;
    /* a detail probe's records and its sight mask */
    double per = (double)probe_bytes(scene) + 4.0 * SB_PROBES_SIGHT_WORDS;
    double left = p->budget_mb > 0 ? p->budget_mb * 1e6 - (double)taken * (double)probe_bytes(scene) : INFINITY;
    enum sb_result res = SB_OK;
    if (left < per * SB_PROBES_BRICK * SB_PROBES_BRICK) {
        sb_warn("probes: the grid takes all of probes.budget_mb (%g): no detail", p->budget_mb);
        st->detail_placed = true;
        return SB_OK;
    }
    double t0 = sb_now_s();
    bool budget = p->budget_mb > 0;
    int placements = 1;
    res = sb_probe_detail_place(st->rc, &st->bvh, st->level, p, p->detail_spacing_m, budget, &st->detail);
    /* under a budget, past the file's caps is over the budget too */
    bool capped = budget && res == SB_ERR_TOO_LARGE;
    char first[64]; /* what the scene's spacing would take */
    if (capped)
        snprintf(first, sizeof(first), "more than a probe file holds");
    else
        snprintf(first, sizeof(first), "%.3g MB", st->detail.detail_count * per / 1e6);
    int level = 0;
    if (capped || (!res && st->detail.detail_count * per > left)) {
        res = SB_OK;
        /* the first guess: a surface's bricks go with the spacing's
         * square, a room's with its cube; past a cap, the count is not
         * known: half an octave */
        double ratio = capped ? M_SQRT2 : cbrt(st->detail.detail_count * per / left);
        int k = (int)fmax(1.0, ceil(DETAIL_LEVELS * log2(ratio)));
        int fits = 0, over = 0, tried = k; /* the finest level found to fit, the last found over (0: none) */
        struct sb_probe_layout found = {0};
        /* up from the guess until a level fits, then down until one does
         * not: the finest level that fits next to one that does not (the
         * count is not monotonic in the spacing: brick columns snap to
         * the lattice) */
        for (int step = 0; step < 8 * DETAIL_LEVELS && k >= 1 && !(fits && over && fits == over + 1); step++) {
            struct sb_probe_layout trial = {0};
            enum sb_result r = sb_probe_detail_place(st->rc, &st->bvh, st->level, p, detail_level(p->detail_spacing_m, k),
                                                     budget, &trial);
            placements++;
            tried = k > tried ? k : tried;
            if (r && r != SB_ERR_TOO_LARGE) {
                res = r;
                break;
            }
            if (!r && trial.detail_count * per <= left) {
                sb_probe_layout_finish(&found);
                found = trial;
                fits = k--;
            } else {
                /* up by the count's square root (a surface's bricks), at
                 * least a level; past a cap, half an octave */
                double step_up = r ? 0.5 * DETAIL_LEVELS : ceil(DETAIL_LEVELS * 0.5 * log2(trial.detail_count * per / left));
                sb_probe_layout_finish(&trial);
                over = k;
                if (fits)
                    break; /* the level under the finest fit is over */
                k += (int)fmax(1.0, step_up);
            }
            if (k < 1)
                break;
        }
        sb_probe_layout_finish(&st->detail);
        if (!res && !fits) {
            sb_error("probes: no detail spacing up to %g m fits probes.budget_mb (%g): raise the budget or "
                     "probes.detail_spacing_m",
                     detail_level(p->detail_spacing_m, tried), p->budget_mb);
            res = SB_ERR_TOO_LARGE;
        }
        st->detail = found;
        level = fits;
    }
    if (!res && level)
        sb_warn("probes: detail %g m apart would take %s, over what probes.budget_mb (%g) leaves after the "
                "grid (%.3g MB): %.3g m apart instead, %u probes, %.3g MB",
                p->detail_spacing_m, first, p->budget_mb, left / 1e6, detail_level(p->detail_spacing_m, level),
                st->detail.detail_count, st->detail.detail_count * per / 1e6);
    sb_debug("probes: detail placed in %.1f ms (%d placements)", 1e3 * (sb_now_s() - t0), placements);
    st->detail_placed = !res;
    return res;
}

/* Where the probes go: the grid's, the detail's, the explicit ones. A
 * grid of layers needs the raycaster (st->rc) to find its columns'
 * surfaces; without `surfaces` (the bounce, which takes the visibility's
 * positions) its layers stand over y 0. Detail needs the raycaster. */
static enum sb_result place(struct probes_state *st, const struct sb_scene *scene, struct sb_probe_layout *layout,
                            float **positions, uint32_t *count, bool surfaces)
{
    const struct sb_level *level = st->level;
    const struct sb_probe_params *p = &scene->probes;
    uint64_t grid;
    enum sb_result res = plan(scene, level, false, layout, &grid);
    if (!res)
        res = place_detail(st, scene, grid + (uint64_t)p->explicit_count);
    if (res)
        return res;
    uint32_t detail = st->detail.detail_count;
    if (detail) {
        if (grid + detail + (uint64_t)p->explicit_count > SB_PROBES_MAX_COUNT) {
            sb_error("probes: %llu grid, %u detail and %d explicit probes; at most %u: raise probes.spacing_m or "
                     "probes.detail_spacing_m, or set probes.budget_mb",
                     (unsigned long long)grid, detail, p->explicit_count, SB_PROBES_MAX_COUNT);
            return SB_ERR_TOO_LARGE;
        }
        struct sb_probe_layout copy;
        if (sb_probe_layout_copy(&copy, &st->detail))
            return SB_ERR_NOMEM;
        layout->detail_spacing_m = copy.detail_spacing_m;
        memcpy(layout->detail_origin_m, copy.detail_origin_m, sizeof(layout->detail_origin_m));
        layout->detail_count = copy.detail_count;
        layout->column_count = copy.column_count;
        layout->columns = copy.columns;
    }
    layout->explicit_count = (uint32_t)p->explicit_count;
    layout->ray_count = p->rays;
    *count = (uint32_t)grid + detail + (uint32_t)p->explicit_count;
    *positions = malloc((size_t)*count * 3 * sizeof(float));
    if (!*positions)
        return SB_ERR_NOMEM;
    float *ground = NULL;
    if (layout->layer_count && grid) {
        ground = calloc((size_t)layout->grid[0] * layout->grid[2], sizeof(*ground));
        if (!ground)
            return SB_ERR_NOMEM;
        if (surfaces && (res = column_surfaces(st, layout, ground))) {
            free(ground);
            return res;
        }
    }
    for (uint32_t i = 0; i < grid; i++) {
        uint32_t c[3] = {i % layout->grid[0], i / layout->grid[0] % layout->grid[1],
                         i / layout->grid[0] / layout->grid[1]};
        for (int k = 0; k < 3; k++)
            (*positions)[3 * (size_t)i + k] = (float)(layout->origin_m[k] + (double)c[k] * layout->spacing_m[k]);
        if (ground)
            (*positions)[3 * (size_t)i + 1] = ground[c[0] + layout->grid[0] * c[2]] + layout->layers_m[c[1]];
    }
    free(ground);
    sb_probe_detail_positions(layout, *positions + 3 * grid);
    for (int e = 0; e < p->explicit_count; e++)
        for (int k = 0; k < 3; k++)
            (*positions)[3 * (grid + detail + e) + k] = (float)p->positions_m[e][k];
    return SB_OK;
}

/*
 * Probes with more back-face hits than the scene allows sit inside
 * geometry: try the candidate offsets, all in one batch of few rays, and
 * move each to the first that is free; flag the rest invalid. unit[i]:
 * the spacing of the probes around probe i (the steps scale with it), its
 * sign whether it is a detail probe.
 */
static enum sb_result push_out(struct sb_raycaster *rc, const struct sb_scene *scene, const float *unit,
                               float *positions, float *offsets, float *valid, const float *results, uint32_t count,
                               uint32_t *inside, uint32_t *pushed, double *gpu_ms)
{
    enum { STEPS = sizeof(push_steps) / sizeof(push_steps[0]), PER = 26 };
    uint32_t *which = NULL, n = 0;
    float *candidates = NULL, *trial = NULL;
    enum sb_result res = SB_OK;
    for (uint32_t i = 0; i < count; i++) {
        valid[i] = results[SB_VISIBILITY_FLOATS * (size_t)i + SB_PROBE_SH] <= scene->probes.inside_fraction;
        n += valid[i] == 0.0f;
    }
    *inside = n;
    *pushed = 0;
    if (gpu_ms)
        *gpu_ms = 0;
    if (!n)
        return SB_OK;
    which = malloc(n * sizeof(*which));
    candidates = malloc((size_t)n * PER * 3 * sizeof(float));
    trial = malloc((size_t)n * PER * SB_VISIBILITY_FLOATS * sizeof(float));
    if (!which || !candidates || !trial) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    /* the candidates a step at a time, nearest first, each step for the
     * probes no step before moved: the first candidate in order that is
     * not inside, as if all were cast at once */
    for (size_t s = 0; s < STEPS && !res; s++) {
        n = 0;
        for (uint32_t i = 0; i < count; i++)
            if (valid[i] == 0.0f)
                which[n++] = i;
        if (!n)
            break;
        for (uint32_t j = 0; j < n; j++) {
            int c = 0;
            bool detail = unit[which[j]] < 0;
            double size = fabs((double)unit[which[j]]);
            for (int d = 0; d < 27; d++) {
                if (d == 13)
                    continue; /* the probe itself */
                int dx = d % 3 - 1, dy = d / 3 % 3 - 1, dz = d / 9 - 1;
                double len = sqrt((double)(dx * dx + dy * dy + dz * dz)),
                       step = (detail ? detail_push_steps : push_steps)[s] * size / len;
                float *q = &candidates[3 * ((size_t)j * PER + c++)];
                q[0] = (float)(positions[3 * (size_t)which[j]] + dx * step);
                q[1] = (float)(positions[3 * (size_t)which[j] + 1] + dy * step);
                q[2] = (float)(positions[3 * (size_t)which[j] + 2] + dz * step);
            }
        }
        struct sb_sky_visibility_params quick = {.ray_count = PUSH_RAYS,
                                                 .tmax_m = (float)reach_of(&scene->probes),
                                                 .what = "sky_visibility: places to push probes out to"};
        double ms = 0;
        if ((res = sb_sky_visibility_bake(rc, candidates, n * PER, &quick, trial, &ms)))
            break;
        if (gpu_ms)
            *gpu_ms += ms;
        for (uint32_t j = 0; j < n; j++)
            for (int c = 0; c < PER; c++) {
                const float *r = &trial[SB_VISIBILITY_FLOATS * ((size_t)j * PER + c)];
                if (r[SB_PROBE_SH] > scene->probes.inside_fraction)
                    continue;
                uint32_t i = which[j];
                for (int k = 0; k < 3; k++) {
                    float to = candidates[3 * ((size_t)j * PER + c) + k];
                    offsets[3 * (size_t)i + k] = to - positions[3 * (size_t)i + k];
                    positions[3 * (size_t)i + k] = to;
                }
                valid[i] = 1.0f;
                (*pushed)++;
                break;
            }
    }
done:
    free(which);
    free(candidates);
    free(trial);
    return res;
}

/* Deringing, a probe at a time on every core (each probe's own: the same
 * result whatever the thread count). */
struct dering_job {
    const float *results;
    double *window, *before;
    double (*sh)[SB_PROBE_SH];
};

static void dering_one(void *user, int i)
{
    struct dering_job *job = user;
    for (int k = 0; k < SB_PROBE_SH; k++)
        job->sh[i][k] = job->results[(size_t)i * SB_VISIBILITY_FLOATS + k];
    job->window[i] = sb_sh9_dering(job->sh[i], &job->before[i]);
}

/*
 * A bake's tiles (docs/probes.md, "Tiles"): each tile's key, whether it is
 * cast, kept from the pack there before (its key unchanged) or left
 * unbaked (a bake of other tiles alone), and the probes to cast.
 */
enum tile_fate { TILE_CAST, TILE_KEPT, TILE_LEFT };

struct tile_plan {
    struct sb_probe_tiling tiling;                  /* count 0: no tiles */
    struct sb_probe_tiling prev[SB_BAKE_MAX_SOURCES]; /* each earlier pack's (count 0: none usable) */
    uint8_t *fate;                                  /* per tile */
    uint8_t *source;                                /* per kept tile: the earlier pack it comes from */
    uint32_t *prev_tile;                            /* per kept tile: its index there */
    uint32_t *cast, cast_count;                     /* the probes to cast, increasing */
    uint32_t counts[3];                             /* tiles by fate */
};

static void tile_plan_finish(struct tile_plan *plan)
{
    sb_probe_tiling_finish(&plan->tiling);
    for (int k = 0; k < SB_BAKE_MAX_SOURCES; k++)
        sb_probe_tiling_finish(&plan->prev[k]);
    free(plan->fate);
    free(plan->source);
    free(plan->prev_tile);
    free(plan->cast);
    memset(plan, 0, sizeof(*plan));
}

/* Tile t's bake key: the product's settings without the world, the tile,
 * the `stride` floats of each of its probes at what[] (where they stand
 * before any push out; the bounce: their visibility records), and the
 * world within `margin` of them. */
static void tile_key(struct probes_state *st, const struct sb_scene *scene, enum sb_product_id id,
                     const struct sb_probe_layout *layout, const struct tile_plan *plan, uint32_t t,
                     const float *what, uint32_t stride, double margin, char out[33])
{
    const struct sb_probe_tiling *tiling = &plan->tiling;
    uint64_t grid = (uint64_t)layout->grid[0] * layout->grid[1] * layout->grid[2];
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    uint32_t grid_probes = 0;
    XXH3_state_t *h = XXH3_createState();
    if (!h) {
        memset(out, '0', 32);
        out[32] = '\0';
        return;
    }
    XXH3_128bits_reset(h);
    for (uint32_t j = tiling->first[t]; j < tiling->first[t + 1]; j++) {
        uint32_t i = tiling->order[j];
        const float *w = &what[(size_t)i * stride];
        grid_probes += i < grid;
        XXH3_128bits_update(h, w, stride * sizeof(float));
        lo[0] = fmin(lo[0], w[0]);
        hi[0] = fmax(hi[0], w[0]);
        lo[1] = fmin(lo[1], w[2]);
        hi[1] = fmax(hi[1], w[2]);
    }
    XXH128_hash_t probes = XXH3_128bits_digest(h);
    XXH3_freeState(h);
    for (int k = 0; k < 2; k++) {
        lo[k] -= margin;
        hi[k] += margin;
    }
    char world[33];
    sb_level_region_hash(&st->regions, lo, hi, world);
    struct sb_key_text key = {.length = 0};
    sb_key_add(&key, "skybake-probe-tile-v1 format %d skybake %s product %s stored %s recipe %d bvh %d",
               SB_PACK_FORMAT_VERSION, SKYBAKE_VERSION, sb_product_name(id), sb_product_format(id)->pixel_type,
               PROBES_RECIPE, SB_BVH_VERSION);
    key_settings(scene, id, &key);
    sb_key_add(&key, " tile %d %d of %a: %u probes, %u of the grid, detail %a apart, at %016llx%016llx, world %s",
               layout->tiles[t].x, layout->tiles[t].z, (double)layout->tile_m, tiling->first[t + 1] - tiling->first[t],
               grid_probes, (double)layout->detail_spacing_m, (unsigned long long)probes.high64,
               (unsigned long long)probes.low64, world);
    sb_hash_bytes(key.text, key.length < sizeof(key.text) ? key.length : sizeof(key.text) - 1, out);
}

/*
 * Plan a bake of `count` probes: without tiles, cast them all; with, key
 * each tile (tile_key), keep those an earlier pack (the one there, then
 * each --from pack: probes_previous) baked under the same key, leave
 * those a bake of some tiles alone does not name, and cast the rest.
 */
static enum sb_result plan_tiles(struct probes_state *st, const struct sb_scene *scene, enum sb_product_id id,
                                 struct sb_probe_layout *layout, uint32_t count, const float *what, uint32_t stride,
                                 double margin, struct tile_plan *plan)
{
    const struct sb_probe_params *p = &scene->probes;
    memset(plan, 0, sizeof(*plan));
    enum sb_result res = SB_OK;
    if (p->tile_m > 0) {
        res = sb_probe_tiling_make(layout, (float)p->tile_m, count, &plan->tiling);
        if (!res && !(plan->fate = calloc(plan->tiling.count, 1)))
            res = SB_ERR_NOMEM;
        if (!res && !(plan->prev_tile = calloc(plan->tiling.count, sizeof(*plan->prev_tile))))
            res = SB_ERR_NOMEM;
        if (!res && !(plan->source = calloc(plan->tiling.count, 1)))
            res = SB_ERR_NOMEM;
        if (res) {
            tile_plan_finish(plan);
            return res;
        }
        layout->reach_m = (float)reach_of(p);
        /* the earlier packs' tiles as their reader checked them: the same
         * assignment, their own tile records left as they were */
        const struct previous *prev = st->prev[slot(id)];
        uint32_t sources = st->prev_count[slot(id)];
        for (uint32_t k = 0; k < sources; k++) {
            struct sb_probe_layout assigned = prev[k].layout;
            assigned.tiles = NULL;
            if (!(prev[k].layout.tile_m == layout->tile_m && prev[k].image.width &&
                  prev[k].image.channel_count == sb_product_format(id)->channel_count &&
                  !sb_probe_tiling_make(&assigned, prev[k].layout.tile_m, prev[k].image.width, &plan->prev[k]) &&
                  plan->prev[k].count == prev[k].layout.tile_count))
                sb_probe_tiling_finish(&plan->prev[k]); /* count 0: not used */
            free(assigned.tiles);
        }
        for (uint32_t t = 0; t < plan->tiling.count; t++) {
            struct sb_probe_tile *tile = &layout->tiles[t];
            tile_key(st, scene, id, layout, plan, t, what, stride, margin, tile->key);
            bool named = !p->only_tile_count;
            for (int i = 0; i < p->only_tile_count; i++)
                named |= p->only_tiles[i][0] == tile->x && p->only_tiles[i][1] == tile->z;
            plan->fate[t] = named ? TILE_CAST : TILE_LEFT;
            /* the first earlier pack that baked it under the same key */
            for (uint32_t k = 0; k < sources && plan->fate[t] != TILE_KEPT; k++) {
                int64_t was = plan->prev[k].count ? sb_probe_tile_find(&prev[k].layout, tile->x, tile->z) : -1;
                const struct sb_probe_tile *there = was >= 0 ? &prev[k].layout.tiles[was] : NULL;
                if (there && (there->flags & SB_PROBES_TILE_BAKED) && there->probes == tile->probes &&
                    !strcmp(there->key, tile->key)) {
                    plan->fate[t] = TILE_KEPT;
                    plan->source[t] = (uint8_t)k;
                    plan->prev_tile[t] = (uint32_t)was;
                }
            }
            plan->counts[plan->fate[t]]++;
        }
        for (int i = 0; i < p->only_tile_count; i++) {
            bool found = false;
            for (uint32_t t = 0; t < plan->tiling.count && !found; t++)
                found = p->only_tiles[i][0] == layout->tiles[t].x && p->only_tiles[i][1] == layout->tiles[t].z;
            if (!found)
                sb_warn("%s: --tile %d,%d holds no probe (tiles of %g m from x = z = 0)", sb_product_name(id),
                        p->only_tiles[i][0], p->only_tiles[i][1], p->tile_m);
        }
    }
    if (!(plan->cast = malloc((count ? count : 1) * sizeof(*plan->cast)))) {
        tile_plan_finish(plan);
        return SB_ERR_NOMEM;
    }
    for (uint32_t i = 0; i < count; i++)
        if (!plan->tiling.count || plan->fate[plan->tiling.tile_of[i]] == TILE_CAST)
            plan->cast[plan->cast_count++] = i;
    return SB_OK;
}

/* The records (and a visibility's sight masks) of the tiles kept, from
 * the earlier packs into image and layout, and each tile's flags and
 * content (the others' keys cleared). */
static void finish_tiles(struct probes_state *st, enum sb_product_id id, const struct tile_plan *plan,
                         struct sb_probe_layout *layout, struct sb_image *image, bool half)
{
    uint64_t grid = (uint64_t)layout->grid[0] * layout->grid[1] * layout->grid[2];
    uint32_t channels = image->channel_count;
    for (uint32_t t = 0; t < plan->tiling.count; t++) {
        struct sb_probe_tile *tile = &layout->tiles[t];
        if (plan->fate[t] == TILE_KEPT) {
            const struct previous *source = &st->prev[slot(id)][plan->source[t]];
            const struct sb_probe_layout *prev = &source->layout;
            const struct sb_probe_tiling *was_tiling = &plan->prev[plan->source[t]];
            uint64_t prev_grid = (uint64_t)prev->grid[0] * prev->grid[1] * prev->grid[2];
            uint32_t was = plan->prev_tile[t];
            for (uint32_t j = 0; j < tile->probes; j++) {
                uint32_t to = plan->tiling.order[plan->tiling.first[t] + j];
                uint32_t from = was_tiling->order[was_tiling->first[was] + j];
                memcpy(&image->data[(size_t)to * channels], &source->image.data[(size_t)from * channels],
                       channels * sizeof(float));
                if (layout->sight && prev->sight && to >= grid && from >= prev_grid)
                    memcpy(&layout->sight[(to - grid) * SB_PROBES_SIGHT_WORDS],
                           &prev->sight[(from - prev_grid) * SB_PROBES_SIGHT_WORDS],
                           SB_PROBES_SIGHT_WORDS * sizeof(*layout->sight));
            }
        }
        if (plan->fate[t] == TILE_LEFT) {
            tile->flags = 0;
            tile->key[0] = '\0';
            tile->content = 0;
        } else {
            tile->flags = SB_PROBES_TILE_BAKED;
        }
    }
    for (uint32_t t = 0; t < plan->tiling.count; t++)
        if (plan->fate[t] != TILE_LEFT)
            layout->tiles[t].content = sb_probe_tile_content(layout, image, half,
                                                             &plan->tiling.order[plan->tiling.first[t]],
                                                             plan->tiling.first[t + 1] - plan->tiling.first[t]);
}

/* What the bake says of its tiles, in the log and the settings. */
static void report_tiles(enum sb_product_id id, const struct tile_plan *plan, struct sb_artifact *a)
{
    if (!plan->tiling.count)
        return;
    sb_info("%s: %u tiles: %u baked, %u kept (their keys unchanged), %u left for another bake", sb_product_name(id),
            plan->tiling.count, plan->counts[TILE_CAST], plan->counts[TILE_KEPT], plan->counts[TILE_LEFT]);
    sb_settings_json_add(a->settings_json, sizeof(a->settings_json),
                         ",\"tiles\":{\"count\":%u,\"baked\":%u,\"kept\":%u,\"left\":%u,\"side_m\":%.9g,"
                         "\"reach_m\":%.9g}",
                         plan->tiling.count, plan->counts[TILE_CAST], plan->counts[TILE_KEPT],
                         plan->counts[TILE_LEFT], (double)a->probes.tile_m, (double)a->probes.reach_m);
}

/* The visibility bake's steps over the probes it casts (`n` of them, at
 * positions[], unit[] as push_out reads it; lattice[] the detail probes'
 * lattice points, NaN for the others): cast, push out, cast again where
 * any moved, the detail's sight masks (into sight[], SB_PROBES_SIGHT_WORDS
 * a probe, for the detail probes only), deringing. */
struct cast {
    uint32_t n;
    float *positions, *unit, *lattice, *offsets, *valid, *results;
    uint32_t *sight;
    struct dering_job dering;
    uint32_t inside, pushed;
};

static void cast_finish(struct cast *c)
{
    free(c->positions);
    free(c->unit);
    free(c->lattice);
    free(c->offsets);
    free(c->valid);
    free(c->results);
    free(c->sight);
    free(c->dering.window);
    free(c->dering.before);
    free(c->dering.sh);
}

static enum sb_result cast_probes(struct probes_state *st, const struct sb_scene *scene, double detail_spacing,
                                  struct cast *c, double *gpu_ms)
{
    struct sb_raycaster *rc = st->rc;
    uint32_t n = c->n, detail = 0;
    c->offsets = calloc((size_t)n * 3 + 1, sizeof(float));
    c->valid = calloc((size_t)n + 1, sizeof(float));
    c->results = malloc(((size_t)n * SB_VISIBILITY_FLOATS + 1) * sizeof(float));
    c->dering.window = malloc(((size_t)n + 1) * sizeof(double));
    c->dering.before = malloc(((size_t)n + 1) * sizeof(double));
    c->dering.sh = malloc(((size_t)n + 1) * sizeof(double[SB_PROBE_SH]));
    if (!c->offsets || !c->valid || !c->results || !c->dering.window || !c->dering.before || !c->dering.sh)
        return SB_ERR_NOMEM;
    c->dering.results = c->results;
    if (!n)
        return SB_OK;
    struct sb_sky_visibility_params params = {.ray_count = scene->probes.rays,
                                              .tmax_m = (float)reach_of(&scene->probes),
                                              .what = "sky_visibility: probes' rays"};
    double ms = 0, t0 = sb_now_s(), t1, t2;
    enum sb_result res = sb_sky_visibility_bake(rc, c->positions, n, &params, c->results, &ms);
    if (res)
        return res;
    *gpu_ms += ms;
    t1 = sb_now_s();
    if ((res = push_out(rc, scene, c->unit, c->positions, c->offsets, c->valid, c->results, n, &c->inside, &c->pushed,
                        &ms)))
        return res;
    *gpu_ms += ms; /* the candidate places of the probes inside */
    t2 = sb_now_s();
    if (c->pushed) { /* the probes pushed out cast again where they went (each probe's rays its own) */
        float *at = malloc((size_t)c->pushed * 3 * sizeof(float));
        float *again = malloc((size_t)c->pushed * SB_VISIBILITY_FLOATS * sizeof(float));
        uint32_t *which = malloc(c->pushed * sizeof(uint32_t)), m = 0;
        res = at && again && which ? SB_OK : SB_ERR_NOMEM;
        for (uint32_t i = 0; i < n && !res; i++) {
            const float *o = &c->offsets[3 * (size_t)i];
            if ((o[0] != 0 || o[1] != 0 || o[2] != 0) && m < c->pushed) {
                memcpy(&at[3 * (size_t)m], &c->positions[3 * (size_t)i], 3 * sizeof(float));
                which[m++] = i;
            }
        }
        if (!res && (res = sb_sky_visibility_bake(rc, at, m, &params, again, &ms)) == SB_OK) {
            for (uint32_t j = 0; j < m; j++)
                memcpy(&c->results[(size_t)which[j] * SB_VISIBILITY_FLOATS], &again[(size_t)j * SB_VISIBILITY_FLOATS],
                       SB_VISIBILITY_FLOATS * sizeof(float));
            *gpu_ms += ms;
        }
        free(at);
        free(again);
        free(which);
        if (res)
            return res;
    }
    double t3 = sb_now_s();
    for (uint32_t i = 0; i < n; i++)
        detail += c->unit[i] < 0;
    if (detail) { /* the detail's sight masks, from where its probes ended up */
        float *from = malloc((size_t)detail * 3 * sizeof(float)), *to = malloc((size_t)detail * 3 * sizeof(float));
        c->sight = malloc((size_t)detail * SB_PROBES_SIGHT_WORDS * sizeof(*c->sight));
        res = from && to && c->sight ? SB_OK : SB_ERR_NOMEM;
        for (uint32_t i = 0, d = 0; i < n && !res; i++)
            if (c->unit[i] < 0) {
                memcpy(&from[3 * (size_t)d], &c->positions[3 * (size_t)i], 3 * sizeof(float));
                memcpy(&to[3 * (size_t)d++], &c->lattice[3 * (size_t)i], 3 * sizeof(float));
            }
        if (!res)
            res = sb_probe_sight_bake(rc, from, to, detail, (float)detail_spacing, c->sight, &ms);
        free(from);
        free(to);
        if (res)
            return res;
        *gpu_ms += ms;
    }
    sb_debug("sky_visibility: %u probes cast in %.1f ms, %u inside tried at up to %u places each in %.1f ms, %u "
             "pushed out cast again in %.1f ms; %u sight masks in %.1f ms",
             n, 1e3 * (t1 - t0), c->inside, 26 * (unsigned)(sizeof(push_steps) / sizeof(push_steps[0])),
             1e3 * (t2 - t1), c->pushed, 1e3 * (t3 - t2), detail, 1e3 * (sb_now_s() - t3));
    double dering_t0 = sb_now_s();
    sb_parallel_for((int)n, dering_one, &c->dering);
    sb_debug("sky_visibility: deringing in %.1f ms", 1e3 * (sb_now_s() - dering_t0));
    return SB_OK;
}

static enum sb_result bake_visibility(struct probes_state *st, const struct sb_scene *scene, struct sb_image *image,
                                      struct sb_artifact *a)
{
    float *positions = NULL;
    uint32_t count = 0, deringed = 0, invalid = 0;
    double lowest = 0, gpu_ms = 0;
    struct sb_probe_layout *layout = &a->probes;
    memset(layout, 0, sizeof(*layout));
    struct tile_plan plan = {0};
    struct cast c = {0};
    const struct sb_probe_params *p = &scene->probes;
    const struct sb_level *level = st->level;
    double placed = sb_now_s();
    enum sb_result res = place(st, scene, layout, &positions, &count, true);
    if (res)
        goto done;
    sb_debug("sky_visibility: %u probes placed in %.1f ms", count, 1e3 * (sb_now_s() - placed));
    uint64_t grid = (uint64_t)layout->grid[0] * layout->grid[1] * layout->grid[2];
    double grid_unit = p->spacing_m > 0 ? p->spacing_m : 1.0, detail_unit = layout->detail_spacing_m;
    /* what a tile's probes see: their rays' reach from where a push out
     * may move them, or the sight masks' cells (the bounce's tiles grow
     * by its own rays' reach: bake_bounce) */
    double margin = 0.6 * fmax(grid_unit, detail_unit) + fmax(reach_of(p), 3.5 * detail_unit) + 0.01;
    if ((res = plan_tiles(st, scene, SB_PRODUCT_SKY_VISIBILITY, layout, count, positions, 3, margin, &plan)))
        goto done;
    c.n = plan.cast_count;
    c.positions = malloc(((size_t)c.n + 1) * 3 * sizeof(float));
    c.unit = malloc(((size_t)c.n + 1) * sizeof(float));
    c.lattice = malloc(((size_t)c.n + 1) * 3 * sizeof(float));
    if (!c.positions || !c.unit || !c.lattice) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    for (uint32_t j = 0; j < c.n; j++) {
        uint32_t i = plan.cast[j];
        bool detail = i >= grid && i < grid + layout->detail_count;
        memcpy(&c.positions[3 * (size_t)j], &positions[3 * (size_t)i], 3 * sizeof(float));
        c.unit[j] = detail ? -(float)detail_unit : (float)grid_unit;
        /* a detail probe's place before any push out is its lattice
         * point, its sight mask's centre */
        for (int k = 0; k < 3; k++)
            c.lattice[3 * (size_t)j + k] = detail ? positions[3 * (size_t)i + k] : NAN;
    }
    if ((res = cast_probes(st, scene, detail_unit, &c, &gpu_ms)))
        goto done;
    if ((res = sb_image_init(image, count, 1, SB_SKY_VISIBILITY_CHANNEL_COUNT)))
        goto done;
    sb_image_set_channel_names(image, SB_SKY_VISIBILITY_CHANNELS);
    if (layout->detail_count &&
        !(layout->sight = calloc((size_t)layout->detail_count * SB_PROBES_SIGHT_WORDS, sizeof(*layout->sight)))) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    for (uint32_t j = 0, d = 0; j < c.n; j++) {
        uint32_t i = plan.cast[j];
        float *o = &image->data[(size_t)i * SB_SKY_VISIBILITY_CHANNEL_COUNT];
        const float *r = &c.results[(size_t)j * SB_VISIBILITY_FLOATS];
        const double *sh = c.dering.sh[j], window = c.dering.window[j];
        deringed += window > 0;
        lowest = fmin(lowest, c.dering.before[j]);
        for (int k = 0; k < 3; k++) {
            o[SB_SKY_VISIBILITY_POSITION + k] = c.positions[3 * (size_t)j + k];
            o[SB_SKY_VISIBILITY_OFFSET + k] = c.offsets[3 * (size_t)j + k];
        }
        o[SB_SKY_VISIBILITY_VALID] = c.valid[j];
        o[SB_SKY_VISIBILITY_BACK_FRACTION] = r[SB_PROBE_SH];
        o[SB_SKY_VISIBILITY_HIT_FRACTION] = r[SB_PROBE_SH + 1];
        o[SB_SKY_VISIBILITY_MEAN_DISTANCE] = r[SB_PROBE_SH + 2];
        o[SB_SKY_VISIBILITY_DERING_WINDOW] = (float)window;
        /* |c_k| <= sqrt(4 pi), the norm of a visibility in [0, 1]: a probe
         * that sees no geometry at all may sum a rounding past it in fp32 */
        const double most = 3.5449075698852539; /* the largest float within sqrt(4 pi) */
        for (int k = 0; k < SB_PROBE_SH; k++)
            o[SB_SKY_VISIBILITY_SH + k] = (float)fmin(fmax(sh[k], -most), most);
        if (c.unit[j] < 0)
            memcpy(&layout->sight[(i - grid) * SB_PROBES_SIGHT_WORDS], &c.sight[(size_t)d++ * SB_PROBES_SIGHT_WORDS],
                   SB_PROBES_SIGHT_WORDS * sizeof(*layout->sight));
    }
    if (plan.tiling.count)
        finish_tiles(st, SB_PRODUCT_SKY_VISIBILITY, &plan, layout, image, false);
    for (uint32_t i = 0; i < count; i++)
        invalid += image->data[(size_t)i * SB_SKY_VISIBILITY_CHANNEL_COUNT + SB_SKY_VISIBILITY_VALID] == 0;
    a->gpu_ms = gpu_ms;
    snprintf(a->settings_json, sizeof(a->settings_json),
             "{\"rays\":%u,\"grid\":[%u,%u,%u],\"spacing_m\":%.9g,\"explicit\":%u,\"triangles\":%llu,"
             "\"inside\":%u,\"pushed_out\":%u,\"invalid\":%u,\"deringed\":%u,\"lowest_before_dering\":%.6g}",
             layout->ray_count, layout->grid[0], layout->grid[1], layout->grid[2], (double)layout->spacing_m[0],
             layout->explicit_count, (unsigned long long)level->placed_triangles, c.inside, c.pushed, invalid,
             deringed, lowest);
    /* the budget's and the layers' fields only where the scene has them:
     * the settings of other bakes as they were */
    if (p->budget_mb > 0)
        sb_settings_json_add(a->settings_json, sizeof(a->settings_json), ",\"bytes\":%llu,\"budget_mb\":%.9g",
                             (unsigned long long)count * probe_bytes(scene) +
                                 (unsigned long long)layout->detail_count * 4 * SB_PROBES_SIGHT_WORDS,
                             p->budget_mb);
    if (layout->layer_count) {
        char heights[SB_PROBES_MAX_LAYERS * 18] = "";
        for (uint32_t l = 0; l < layout->layer_count; l++)
            snprintf(heights + strlen(heights), sizeof(heights) - strlen(heights), "%s%.9g", l ? "," : "",
                     (double)layout->layers_m[l]);
        sb_settings_json_add(a->settings_json, sizeof(a->settings_json), ",\"layers_m\":[%s]", heights);
    }
    if (layout->column_count)
        sb_settings_json_add(a->settings_json, sizeof(a->settings_json),
                             ",\"detail\":{\"spacing_m\":%.9g,\"brick_columns\":%u,\"probes\":%u}",
                             (double)layout->detail_spacing_m, layout->column_count, layout->detail_count);
    report_tiles(SB_PRODUCT_SKY_VISIBILITY, &plan, a);
    sb_artifact_set_world(a, st->mesh_hash, st->path);
    sb_info("sky_visibility: %u probes over %llu triangles (%u in detail); %u cast: %u inside geometry, %u pushed "
            "out; %u deringed",
            count, (unsigned long long)level->placed_triangles, layout->detail_count, c.n, c.inside, c.pushed,
            deringed);
done:
    if (res)
        sb_image_finish(image);
    tile_plan_finish(&plan);
    cast_finish(&c);
    free(positions);
    return res;
}

/* The bounce (sky_bounce) or the sun's (sun_bounce) at the visibility's
 * probes (their positions after any push out; invalid ones get zeros),
 * over the same grid. */
static enum sb_result bake_bounce(struct probes_state *st, const struct sb_scene *scene, enum sb_product_id id,
                                  const struct sb_image *visibility, struct sb_image *image, struct sb_artifact *a)
{
    bool sun = id == SB_PRODUCT_SUN_BOUNCE;
    const char *name = sb_product_name(id);
    const uint32_t floats = sun ? SB_BOUNCE_SUN_TABLE : SB_BOUNCE_FLOATS;
    float *positions = NULL, *valid = NULL, *out = NULL;
    uint32_t count = 0;
    struct sb_probe_layout *layout = &a->probes;
    memset(layout, 0, sizeof(*layout));
    struct tile_plan plan = {0};
    enum sb_result res = place(st, scene, layout, &positions, &count, false);
    if (!res && (visibility->width != count || visibility->channel_count != SB_SKY_VISIBILITY_CHANNEL_COUNT)) {
        sb_error("%s: sky_visibility holds %u probes, the scene places %u", name, visibility->width, count);
        res = SB_ERR_BAD_IMAGE;
    }
    /* a tile's bounce reads its visibility records and the world its
     * rays and their surfaces' rays reach */
    double margin = 2 * reach_of(&scene->probes) + 0.01;
    if (res || (res = plan_tiles(st, scene, id, layout, count, visibility->data,
                                 SB_SKY_VISIBILITY_CHANNEL_COUNT, margin, &plan)))
        goto done;
    uint32_t n = plan.cast_count;
    valid = malloc(((size_t)n + 1) * sizeof(float));
    out = malloc(((size_t)n * floats + 1) * sizeof(float));
    if (!valid || !out) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    uint32_t valid_count = 0;
    for (uint32_t j = 0; j < n; j++) {
        const float *v = &visibility->data[(size_t)plan.cast[j] * SB_SKY_VISIBILITY_CHANNEL_COUNT];
        memcpy(&positions[3 * (size_t)j], v, 3 * sizeof(float));
        valid[j] = v[SB_SKY_VISIBILITY_VALID];
        valid_count += v[SB_SKY_VISIBILITY_VALID] != 0;
    }
    struct sb_sky_bounce_params params = {.ray_count = sun ? scene->probes.sun_rays : scene->probes.bounce_rays,
                                          .secondary = sun ? 0 : scene->probes.bounce_secondary,
                                          .bounces = scene->probes.bounces,
                                          .tmax_m = (float)reach_of(&scene->probes),
                                          .sun = sun};
    struct sb_sky_bounce_report report = {0};
    if (!st->surfaces.material_count && (res = sb_surfaces_create_level(st->rc->vk, st->level, &st->surfaces)))
        goto done;
    if ((n && (res = sb_sky_bounce_bake(st->rc, &st->surfaces, positions, valid, n, &params, out, &a->gpu_ms,
                                        &report))) ||
        (res = sb_image_init(image, count, 1, floats)))
        goto done;
    sb_image_set_channel_names(image, sun ? SB_SUN_BOUNCE_CHANNELS : SB_SKY_BOUNCE_CHANNELS);
    for (uint32_t j = 0; j < n; j++)
        memcpy(&image->data[(size_t)plan.cast[j] * floats], &out[(size_t)j * floats], floats * sizeof(float));
    int64_t bad; /* stored as binary16 (its file's values): 4.9e-4 relative, its range +-6.7 */
    if ((res = sb_image_round_to_half(image, &bad))) {
        sb_error("%s: value %lld does not fit binary16", name, (long long)bad);
        goto done;
    }
    if (plan.tiling.count)
        finish_tiles(st, id, &plan, layout, image, true);
    snprintf(a->settings_json, sizeof(a->settings_json),
             "{\"rays\":%u,\"secondary\":%u,\"grid\":[%u,%u,%u],\"spacing_m\":%.9g,\"explicit\":%u,"
             "\"valid\":%u,\"bounces\":%u,\"bounces_summed\":%u,\"added_mean\":%.4g,\"added_most\":%.4g,"
             "\"model\":\"%s; bounces past the first lit by the probe's own light\"}",
             params.ray_count, params.secondary, layout->grid[0], layout->grid[1], layout->grid[2],
             (double)layout->spacing_m[0], layout->explicit_count, valid_count, params.bounces, report.most_bounces,
             report.mean_added, report.most_added,
             sun ? "Lambertian bounces of a sun from 12 x 12 directions over the upper hemisphere's octahedral map, "
                   "each the mean of its bilinear neighbourhood; order-1 SH at the probe, grey, times one rgb shape"
                 : "Lambertian bounces; order-1 SH at the probe x order-2 SH of the light at the surfaces");
    report_tiles(id, &plan, a);
    char summed[160]; /* how the bounces were summed, and what the later ones added */
    if (params.bounces == 1)
        snprintf(summed, sizeof(summed), "one bounce");
    else if (params.bounces)
        snprintf(summed, sizeof(summed), "%u bounces", params.bounces);
    else if (report.most_bounces)
        snprintf(summed, sizeof(summed), "every bounce (in closed form, or a series of up to %u where it might not "
                 "converge)", report.most_bounces);
    else
        snprintf(summed, sizeof(summed), "every bounce (in closed form)");
    if (params.bounces != 1) {
        size_t used = strlen(summed);
        snprintf(summed + used, sizeof(summed) - used, ", the later ones adding %.1f%% to the first on average, "
                 "%.1f%% at most", 100 * report.mean_added, 100 * report.most_added);
    }
    if (sun)
        sb_info("sun_bounce: %u probes (%u cast, %u of them valid), %u rays each, %u sun directions from each surface "
                "hit; %s", count, n, valid_count, params.ray_count, SB_SUN_DIRECTIONS, summed);
    else
        sb_info("sky_bounce: %u probes (%u cast, %u of them valid), %u rays each, %u from each surface hit; %s", count,
                n, valid_count, params.ray_count, params.secondary, summed);
done:
    if (res)
        sb_image_finish(image);
    tile_plan_finish(&plan);
    free(positions);
    free(valid);
    free(out);
    return res;
}

static enum sb_result probes_bake(void *state, struct sb_vk *vk, const struct sb_scene *scene, enum sb_product_id id,
                                  const struct sb_image baked[SB_PRODUCT_COUNT], struct sb_image *image,
                                  struct sb_artifact *a)
{
    struct probes_state *st = state;
    double t0 = sb_now_s();
    bool had = st->rc != NULL;
    enum sb_result res = raycaster(st, scene, vk);
    if (res)
        return res;
    if (!had)
        sb_debug("probes: the BVH built and on the device in %.1f ms", 1e3 * (sb_now_s() - t0));
    return is_bounce(id) ? bake_bounce(st, scene, id, &baked[SB_PRODUCT_SKY_VISIBILITY], image, a)
                         : bake_visibility(st, scene, image, a);
}

static uint32_t probes_kernels(void *state, const struct sb_scene *scene, enum sb_product_id id,
                               struct sb_pipeline_params out[SB_FAMILY_KERNELS_MAX])
{
    const struct probes_state *st = state;
    bool instanced = st->level->instance_count > 0;
    uint32_t n = sb_surfaces_level_kernels(st->level, is_bounce(id), out);
    out[n++] = is_bounce(id) ? sb_sky_bounce_kernel(instanced, id == SB_PRODUCT_SUN_BOUNCE)
                             : sb_sky_visibility_kernel(instanced);
    if (id == SB_PRODUCT_SKY_VISIBILITY && scene->probes.detail_spacing_m > 0)
        out[n++] = sb_probe_sight_kernel(instanced);
    return n;
}

const struct sb_family_baker sb_probes_family = {
    .depends_on = probes_depends_on,
    .key = probes_key,
    .create = probes_create,
    .destroy = probes_destroy,
    .bake = probes_bake,
    .kernels = probes_kernels,
    .previous = probes_previous,
};
