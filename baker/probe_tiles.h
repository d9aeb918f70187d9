/*
 * Tiles of a probe bake (docs/probes.md, "Tiles"): which of a layout's
 * probes each tile holds, and what of the world a tile's probes can see:
 * the placed meshes whose boxes come within the rays' reach of them,
 * hashed into the tile's bake key, so that moving one house rebakes the
 * tiles around it and no other.
 */
#ifndef SB_BAKER_PROBE_TILES_H
#define SB_BAKER_PROBE_TILES_H

#include <stdbool.h>
#include <stdint.h>

#include "probes.h"
#include "result.h"

struct sb_level;
struct sb_bvh;

struct sb_probe_tiling {
    uint32_t count;    /* tiles: the layout's (sb_probe_tiles_assign) */
    uint32_t *tile_of; /* each probe's tile */
    /* tile t's probes, in increasing index: order[first[t]] to
     * order[first[t + 1] - 1] */
    uint32_t *first, *order;
};

/* Assign the layout's `probe_count` probes (a grid and detail, no
 * explicit ones) to tiles `side` metres across (layout->tiles set as
 * sb_probe_tiles_assign sets them). On failure *tiling is zeroed. */
enum sb_result sb_probe_tiling_make(struct sb_probe_layout *layout, float side, uint32_t probe_count,
                                    struct sb_probe_tiling *tiling);
void sb_probe_tiling_finish(struct sb_probe_tiling *tiling);

/* The level's placed meshes as the region hash reads them: each
 * instance's box over x and z and its mesh's hash, and which instances are
 * wide (a terrain, a ground: at least `wide_m` across in x and in z),
 * which every tile sees at any distance (a level that places nothing is
 * one wide mesh). */
struct sb_level_regions {
    const struct sb_level *level;
    uint32_t count;
    double (*box)[4];       /* x lo, z lo, x hi, z hi */
    bool *wide;
    char (*mesh_hash)[33];  /* a mesh's */
    char whole[33];         /* a level that places nothing: its mesh's hash */
};

enum sb_result sb_level_regions_make(const struct sb_level *level, double wide_m, struct sb_level_regions *regions);
void sb_level_regions_finish(struct sb_level_regions *regions);

/* Flag the wide instances' records in the level's BVH (built by
 * sb_level_build_bvh) SB_BVH_INSTANCE_WIDE: a kernel's reach (bvh.glsl's
 * bvh_reach) leaves them out. */
void sb_level_regions_mark(const struct sb_level_regions *regions, struct sb_bvh *bvh);

/* XXH3-128 of what stands over x lo[0]..hi[0], z lo[1]..hi[1]: every
 * instance whose box meets it, and every wide one, in the level's order,
 * by its mesh's hash and its placement (a level that places nothing: its
 * mesh's hash). */
void sb_level_region_hash(const struct sb_level_regions *regions, const double lo[2], const double hi[2],
                          char out[33]);

#endif
