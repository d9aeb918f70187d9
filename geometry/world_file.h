/*
 * skybake world files: a JSON description of a ground plane and boxes and
 * pillars on it, each with a PBR material (docs/skyview.md has the schema;
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

/* Parse a world file's text (source names it in messages) and append its
 * triangles to *mesh, placed by params' transform, with params' albedo
 * overrides. On failure *mesh is left as it was and the message names the
 * source, the field and the reason. params may be NULL. */
enum sb_result sb_world_file_parse(const char *json, size_t size, const char *source,
                                   const struct sb_mesh_load_params *params, struct sb_mesh *mesh);

/* The same from the file at path (at most SB_WORLD_FILE_MAX_BYTES). */
enum sb_result sb_world_file_load(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh);

#endif
