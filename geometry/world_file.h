/*
 * skybake world files: a JSON description of a ground plane and boxes and
 * pillars on it, each with a PBR material, and of files placed on it (mesh
 * files or other world files: a list of instances, and scatters) (docs/skyview.md has the schema;
 * data/worlds/test.json is skyview's default world). One more source of
 * triangles: sb_mesh_load reads a *.json file through here, so the baker's
 * probes and skyview see the same triangles whichever source they come from.
 *
 * Materials are named "ground", "boxes[i]" and "pillars[i]"; the ground
 * receives shadows but casts none. Triangles are wound counter-clockwise
 * seen from outside.
 */
#ifndef SB_GEOMETRY_WORLD_FILE_H
#define SB_GEOMETRY_WORLD_FILE_H

#include <stddef.h>

#include "mesh.h"

#define SB_WORLD_FILE_MAX_BYTES (1 << 20)
#define SB_WORLD_FILE_MAX_OBJECTS 256 /* boxes, and pillars */
#define SB_WORLD_FILE_MAX_REFS 16384  /* instances and scatters */
#define SB_WORLD_FILE_MAX_TERRAIN_CELLS 2048 /* a side: 8 Mi triangles */
#define SB_WORLD_FILE_MAX_SCATTER (1u << 20) /* copies one scatter places */

/* A file a world file places (its "instances" and "scatter"): a mesh file
 * or another world file, read through level.h. */
struct sb_world_file_ref {
    char file[1024];                    /* as written: relative to the world file's folder, or absolute */
    struct sb_mesh_transform transform; /* an instance's placement; a scatter's units_m and up_z */
    /* a scatter: `count` copies over area_m (x0, z0, x1, z1), each turned
     * about y and scaled within scale_range, dropped onto the world file's
     * own triangles and what its "instances" place, by `seed` */
    bool scatter;
    uint32_t count;
    uint64_t seed;
    double area_m[4];
    double scale_range[2];
};

struct sb_world_file_refs {
    int count;
    struct sb_world_file_ref *refs; /* owned: free() */
};

/* Parse a world file's text (source names it in messages) and append its
 * triangles to *mesh, placed by params' transform, with params' albedo
 * overrides; the files it places go to *refs (zeroed first), or, with refs
 * NULL, such a file is refused (a world of instances is read as a level,
 * level.h). On failure *mesh is left as it was, *refs is empty and the
 * message names the source, the field and the reason. params may be NULL. */
enum sb_result sb_world_file_parse(const char *json, size_t size, const char *source,
                                   const struct sb_mesh_load_params *params, struct sb_mesh *mesh,
                                   struct sb_world_file_refs *refs);

/* The same from the file at path (at most SB_WORLD_FILE_MAX_BYTES). */
enum sb_result sb_world_file_load(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh,
                                  struct sb_world_file_refs *refs);

#endif
