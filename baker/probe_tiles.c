#include "probe_tiles.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include "bvh.h"
#include "config.h"
#include "level.h"

enum sb_result sb_probe_tiling_make(struct sb_probe_layout *layout, float side, uint32_t probe_count,
                                    struct sb_probe_tiling *tiling)
{
    memset(tiling, 0, sizeof(*tiling));
    uint32_t n = probe_count ? probe_count : 1;
    tiling->tile_of = malloc(n * sizeof(*tiling->tile_of));
    tiling->order = malloc(n * sizeof(*tiling->order));
    enum sb_result res = tiling->tile_of && tiling->order ? SB_OK : SB_ERR_NOMEM;
    if (!res)
        res = sb_probe_tiles_assign(layout, side, tiling->tile_of);
    if (!res && !(tiling->first = calloc((size_t)layout->tile_count + 1, sizeof(*tiling->first))))
        res = SB_ERR_NOMEM;
    if (res) {
        sb_probe_tiling_finish(tiling);
        return res;
    }
    tiling->count = layout->tile_count;
    /* a counting sort: each tile's probes in increasing index */
    for (uint32_t i = 0; i < probe_count; i++)
        tiling->first[tiling->tile_of[i] + 1]++;
    for (uint32_t t = 0; t < tiling->count; t++)
        tiling->first[t + 1] += tiling->first[t];
    for (uint32_t i = 0; i < probe_count; i++)
        tiling->order[tiling->first[tiling->tile_of[i]]++] = i;
    for (uint32_t t = tiling->count; t > 0; t--)
        tiling->first[t] = tiling->first[t - 1];
    tiling->first[0] = 0;
    return SB_OK;
}

void sb_probe_tiling_finish(struct sb_probe_tiling *tiling)
{
    free(tiling->tile_of);
    free(tiling->first);
    free(tiling->order);
    memset(tiling, 0, sizeof(*tiling));
}

enum sb_result sb_level_regions_make(const struct sb_level *level, double wide_m, struct sb_level_regions *regions)
{
    memset(regions, 0, sizeof(*regions));
    regions->level = level;
    if (!level->instance_count) {
        sb_level_hash(level, regions->whole);
        return SB_OK;
    }
    float (*mesh_box)[6] = malloc(level->mesh_count * sizeof(*mesh_box));
    regions->box = malloc(level->instance_count * sizeof(*regions->box));
    regions->wide = malloc(level->instance_count * sizeof(*regions->wide));
    regions->mesh_hash = malloc(level->mesh_count * sizeof(*regions->mesh_hash));
    if (!mesh_box || !regions->box || !regions->wide || !regions->mesh_hash) {
        free(mesh_box);
        sb_level_regions_finish(regions);
        return SB_ERR_NOMEM;
    }
    for (uint32_t m = 0; m < level->mesh_count; m++) {
        if (!sb_mesh_bounds(&level->meshes[m], mesh_box[m], mesh_box[m] + 3))
            memset(mesh_box[m], 0, sizeof(mesh_box[m]));
        sb_mesh_hash(&level->meshes[m], regions->mesh_hash[m]);
    }
    for (uint32_t i = 0; i < level->instance_count; i++) {
        const struct sb_bvh_instance *in = &level->instances[i];
        const float *b = mesh_box[in->mesh];
        double *box = regions->box[i];
        box[0] = box[1] = INFINITY;
        box[2] = box[3] = -INFINITY;
        for (int corner = 0; corner < 8; corner++) {
            double p[3] = {b[(corner & 1) ? 3 : 0], b[(corner & 2) ? 4 : 1], b[(corner & 4) ? 5 : 2]};
            for (int r = 0; r < 2; r++) { /* x, then z */
                const double *row = in->to_world[2 * r];
                double w = row[0] * p[0] + row[1] * p[1] + row[2] * p[2] + row[3];
                box[r] = fmin(box[r], w);
                box[2 + r] = fmax(box[2 + r], w);
            }
        }
        regions->wide[i] = box[2] - box[0] >= wide_m && box[3] - box[1] >= wide_m;
    }
    free(mesh_box);
    regions->count = level->instance_count;
    return SB_OK;
}

void sb_level_regions_mark(const struct sb_level_regions *regions, struct sb_bvh *bvh)
{
    if (!regions->count || !bvh->instance_count || !bvh->node_count)
        return;
    /* the top level's tree from its root (records are nodes too, and
     * their bytes mean nothing as a node's) */
    uint32_t stack[2 * SB_BVH_MAX_DEPTH + 2], top = 0;
    stack[top++] = 0;
    while (top) {
        const struct sb_bvh_node *node = &bvh->nodes[stack[--top]];
        if (node->count == SB_BVH_INSTANCE_LEAF) {
            struct sb_bvh_instance_record *record = (struct sb_bvh_instance_record *)&bvh->nodes[node->first];
            record->flags =
                record->instance < regions->count && regions->wide[record->instance] ? SB_BVH_INSTANCE_WIDE : 0;
        } else if (node->count == 0 && top + 2 <= sizeof(stack) / sizeof(stack[0])) {
            stack[top++] = node->first;
            stack[top++] = node->first + 1;
        }
    }
}

void sb_level_regions_finish(struct sb_level_regions *regions)
{
    free(regions->box);
    free(regions->wide);
    free(regions->mesh_hash);
    memset(regions, 0, sizeof(*regions));
}

void sb_level_region_hash(const struct sb_level_regions *regions, const double lo[2], const double hi[2],
                          char out[33])
{
    if (!regions->count) {
        memcpy(out, regions->whole, 33);
        return;
    }
    static const char tag[] = "skybake-level-region-v1";
    XXH3_state_t *st = XXH3_createState();
    if (!st) {
        memset(out, '0', 32); /* a key that matches nothing a bake writes */
        out[32] = '\0';
        return;
    }
    XXH3_128bits_reset(st);
    XXH3_128bits_update(st, tag, sizeof(tag));
    for (uint32_t i = 0; i < regions->count; i++) {
        const double *b = regions->box[i];
        if (!regions->wide[i] && (b[0] > hi[0] || b[2] < lo[0] || b[1] > hi[1] || b[3] < lo[1]))
            continue;
        const struct sb_bvh_instance *in = &regions->level->instances[i];
        XXH3_128bits_update(st, regions->mesh_hash[in->mesh], 32);
        XXH3_128bits_update(st, in->to_world, sizeof(in->to_world));
    }
    XXH128_hash_t h = XXH3_128bits_digest(st);
    XXH3_freeState(st);
    snprintf(out, 33, "%016llx%016llx", (unsigned long long)h.high64, (unsigned long long)h.low64);
}
