/*
 * The world skyview draws: one triangle list of vertices with a face
 * normal and a PBR material each, made from a mesh (geometry/mesh.h): a
 * skybake world file (a ground and boxes and pillars, geometry/world_file.h;
 * data/worlds/test.json is built in as the default) or any file assimp
 * reads, placed as a scene's `world` places it.
 */
#ifndef SB_RUNTIME_WORLD_H
#define SB_RUNTIME_WORLD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "result.h"
#include "view_gpu.h"

/* A mesh of an instanced world: vertices [first_vertex, end_vertex) in its
 * own space, those from caster_first_vertex on casting shadows. */
struct sb_world_mesh_range {
    uint32_t first_vertex, caster_first_vertex, end_vertex;
    float caster_min[3], caster_max[3]; /* the casters' box, the mesh's space (empty: min > max) */
    float min[3], max[3];               /* every vertex's */
};

struct sb_world {
    struct sb_vertex_gpu *vertices; /* owned: vertex_count, a triangle list */
    uint32_t vertex_count;
    /* Triangles of materials that cast no shadow (a ground) come first:
     * they receive shadows but are not drawn into the shadow maps. */
    uint32_t caster_first_vertex;
    char mesh_hash[33]; /* sb_mesh_hash of the mesh it was made from (sb_level_hash of a level) */
    /* the images the vertices' texture indices name (owned, with their texels) */
    struct sb_mesh_texture *textures;
    uint32_t texture_count;
    /* the emitting materials the vertices' albedo[3] name (owned) */
    struct sb_emissive_gpu *emissive;
    uint32_t emissive_count;
    /* An instanced world (a level that places meshes): the vertices are
     * its meshes' in turn, each in its own space, and instances (sorted by
     * mesh) place them; caster_first_vertex is then unused. instance_count
     * 0: the vertices are the world, in place. */
    uint32_t mesh_count, instance_count;
    struct sb_world_mesh_range *meshes;   /* owned */
    struct sb_instance_gpu *instances;    /* owned */
    uint32_t *instance_mesh;              /* owned: each instance's mesh */
};

/* Instance i's map of a point of its mesh to the world (fp64 from the fp32 rows). */
void sb_world_place(const struct sb_world *world, uint32_t instance, const float p[3], double out[3]);

/* The box of instance i's casters (or of all its mesh) in the world: its
 * mesh's box placed; false when there is none. */
bool sb_world_instance_box(const struct sb_world *world, uint32_t instance, bool casters, double box[2][3]);

/* Grow lo and hi by the world's casters (every instance's). */
void sb_world_caster_bounds(const struct sb_world *world, double lo[3], double hi[3]);

/* The world of a mesh: flat shading (each triangle's own normal, from its
 * winding), the triangle's material, its textures (copied) and the
 * vertices' texture coordinates and tangents. */
enum sb_result sb_world_from_mesh(const struct sb_mesh *mesh, struct sb_world *world);

/* The world of a level (geometry/level.h), named by the level's hash: one
 * that places nothing as sb_world_from_mesh makes it; else instanced, its
 * meshes once and its instances. */
struct sb_level;
enum sb_result sb_world_from_level(const struct sb_level *level, struct sb_world *world);

/* Read a mesh file (sb_mesh_load: a world file or any format assimp reads)
 * with params (NULL: as the file is) and make its world. On failure the
 * world is zeroed and the message names the file, the field and the reason. */
enum sb_result sb_world_load(const char *path, const struct sb_mesh_load_params *params, struct sb_world *world);

/* A world file's text; source names it in messages. */
enum sb_result sb_world_parse(const char *json, size_t size, const char *source, struct sb_world *world);

/* The world's triangles as a mesh (for a BVH, or Embree): triangle t is
 * vertices 3t to 3t + 2 of all of them, or of those from
 * caster_first_vertex on with casters_only; material 1 (casting shadows)
 * or 0 (receiving only). An instanced world's are placed, instance after
 * instance (at most SB_MESH_MAX_TRIANGLES: the tests' flattened copy). */
enum sb_result sb_world_mesh(const struct sb_world *world, bool casters_only, struct sb_mesh *mesh);

/* A world whose casters span at most this (x or z) is a model: a camera
 * inside its box is inside the model, and is moved out to frame it. */
#define SB_WORLD_MODEL_M 50.0

/*
 * A camera that sees the world: when the one given (camera_m, yaw clockwise
 * from north (-z), pitch above the horizontal, the vertical field of view
 * fov_y, radians, and the frame's width over its height) cannot see the
 * world's shadow casters (their box lies wholly outside its frustum and does
 * not hold it, or holds it but is a model's, SB_WORLD_MODEL_M), set camera_m, yaw and pitch to frame them: looking north
 * and 20 degrees down at their box's centre from where its bounding sphere
 * fills the narrower field of view, at least 0.1 m above the ground.
 * Returns whether it did; a world of no caster is left alone.
 */
bool sb_world_frame(const struct sb_world *world, double aspect, double fov_y, double camera_m[3], double *yaw,
                    double *pitch);

/*
 * A camera under the world's surface (a terrain whose hills rise above
 * it): when an upward face lies above camera_m and none below it (straight
 * up and down), lift it to `eye_m` above the highest upward face there and
 * return true (*surface_m gets that face's height); else leave it.
 */
bool sb_world_lift(const struct sb_world *world, double eye_m, double camera_m[3], double *surface_m);

/* Free the triangles; accepts a zeroed world. */
void sb_world_finish(struct sb_world *world);

#endif
