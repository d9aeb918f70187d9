/*
 * A level: the world a scene names, as unique meshes and the instances
 * that place them (geometry/bvh.h's two levels). A world file's
 * "instances" and "scatter" (world_file.h) place mesh files and other
 * world files, which may place more in turn; each file is read once,
 * however often it is placed. A world that places nothing is one mesh, as
 * sb_mesh_load_world reads it, and everything downstream (its BVH, its
 * hash, the bake keys) is as before.
 *
 * Caps, checked before the arrays they size are allocated: nesting
 * SB_LEVEL_MAX_DEPTH world files deep, no cycle between them (a file that
 * places itself, directly or not), SB_LEVEL_MAX_INSTANCES instances,
 * SB_LEVEL_MAX_PLACED_TRIANGLES placed triangles, and the unique
 * triangles a BVH holds (2^31).
 */
#ifndef SB_GEOMETRY_LEVEL_H
#define SB_GEOMETRY_LEVEL_H

#include <stddef.h>
#include <stdint.h>

#include "bvh.h"
#include "mesh.h"

#define SB_LEVEL_MAX_DEPTH 8
#define SB_LEVEL_MAX_INSTANCES (1u << 22)
#define SB_LEVEL_MAX_PLACED_TRIANGLES (1ull << 36)

struct sb_level {
    uint32_t mesh_count, instance_count; /* instance_count 0: meshes[0] alone, in place */
    struct sb_mesh *meshes;              /* owned */
    struct sb_bvh_instance *instances;   /* owned */
    uint64_t placed_triangles;           /* every instance's triangles */
    /* every mesh's materials in turn, as the BVH numbers them (owned) */
    struct sb_mesh_material *materials;
    uint32_t material_count;
    /* every mesh's textures in turn, as the materials above number them
     * (the array owned, the textures the meshes') */
    const struct sb_mesh_texture **textures;
    uint32_t texture_count;
    /* sb_level_bounds_casting's, found once as the level is read */
    float casting_min[3], casting_max[3];
    bool has_casting_bounds;
};

struct sb_world_params;

/*
 * Read a scene's world (formats/scene.h: its file, relative to `directory`
 * unless absolute or directory is "") with everything it places, files it
 * places relative to the world file that names them. *path_out (may be
 * NULL) gets the world's path, absolute. On failure *level is zeroed and
 * the message names the file, the field and the reason.
 */
enum sb_result sb_level_load(const struct sb_world_params *world, const char *directory, struct sb_level *level,
                             char *path_out, size_t path_size);

/* Free and zero; accepts a zeroed level. */
void sb_level_finish(struct sb_level *level);

/*
 * The same level shared while held: the first acquire reads it (as
 * sb_level_load), later ones of the same world (the same parameters and
 * directory) while it is held get it again, so the families of one bake
 * read a level once. Release with sb_level_release, which frees it when no
 * holder is left and sets *level to NULL. Thread-safe.
 */
enum sb_result sb_level_acquire(const struct sb_world_params *world, const char *directory,
                                const struct sb_level **level, char *path_out, size_t path_size);
void sb_level_release(const struct sb_level **level);

/* The BVH: one level over meshes[0], or two. */
enum sb_result sb_level_build_bvh(const struct sb_level *level, struct sb_bvh *bvh);

/* XXH3-128 of what was read: sb_mesh_hash of meshes[0] for a level that
 * places nothing; else of every mesh's hash and every instance. */
void sb_level_hash(const struct sb_level *level, char out[33]);

/* The bounds of what casts shadows, placed vertex by vertex, else of
 * everything (sb_mesh_bounds_casting); false for an empty level. */
bool sb_level_bounds_casting(const struct sb_level *level, float min[3], float max[3]);

/* Every instance's triangles placed into one mesh (for a renderer that
 * draws one list); SB_ERR_TOO_LARGE past SB_MESH_MAX_TRIANGLES. */
enum sb_result sb_level_flatten(const struct sb_level *level, struct sb_mesh *mesh);

#endif
