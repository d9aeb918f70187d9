/*
 * A world's geometry from a file, whatever the file is: a mesh through
 * assimp (mesh.h) or a skybake world file (world_file.h). The one place
 * that knows both, so that neither knows the other.
 */
#ifndef SB_GEOMETRY_LOAD_H
#define SB_GEOMETRY_LOAD_H

#include <stdbool.h>
#include <stddef.h>

#include "mesh.h"

/*
 * Append the triangles of the mesh file at `path` to *mesh (which may hold
 * triangles already, or be zeroed). Every triangle of every mesh of the
 * file's node tree, with the nodes' transforms; points and lines are left
 * out; polygons are triangulated. Materials take the file's base colour
 * (glTF's baseColorFactor) or else its diffuse colour, clamped to [0, 1],
 * unless an override names them.
 *
 * A file named *.json is a skybake world file instead (world_file.h: a
 * ground, boxes and pillars), built with the same transform and overrides;
 * any other is a mesh (sb_mesh_import).
 *
 * Refuses, naming the file and the reason, and leaving *mesh as it was: a
 * file that cannot be read or is over SB_MESH_MAX_FILE_BYTES
 * (SB_ERR_IO, SB_ERR_TOO_LARGE), one assimp refuses, crashes on or does
 * not finish within the time limit (SB_ERR_MESH), a
 * non-finite or out-of-extent coordinate (SB_ERR_NUMERIC), counts past the
 * caps (SB_ERR_TOO_LARGE), and a file with no triangle of non-zero area
 * (SB_ERR_MESH). Zero-area triangles are left out and counted. A mesh file
 * with params->ground stands on it (sb_mesh_add_ground); a world file with
 * one is refused (SB_ERR_MESH).
 */
enum sb_result sb_mesh_load(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh);

/* Whether sb_mesh_load reads `path` as a skybake world file (its name ends
 * in .json) rather than through assimp. */
bool sb_mesh_is_world_file(const char *path);

/* The path of a scene's world file: relative to `directory` unless
 * absolute or directory is "". */
struct sb_world_params;
void sb_world_path(const struct sb_world_params *world, const char *directory, char *path, size_t size);

/* The scene's albedo overrides as mesh.h's (pointing into *world), into
 * out[SB_WORLD_MAX_OVERRIDES]; returns their count. */
int sb_world_overrides(const struct sb_world_params *world, struct sb_mesh_albedo_override *out);

/* Read a scene's world (formats/scene.h: its file, relative to
 * `directory` unless absolute or directory is "", placed and overridden as
 * the scene says, a mesh file standing on the ground the scene gives it,
 * by default one at its lowest point or 0, sb_mesh_ground); *path_out (may
 * be NULL) gets the path read, absolute. */
enum sb_result sb_mesh_load_world(const struct sb_world_params *world, const char *directory, struct sb_mesh *mesh,
                                  char *path_out, size_t path_size);

/* As sb_mesh_load_world, but a mesh file whose nodes reuse meshes comes as
 * parts (mesh.h's sb_mesh_import_parts), placed where the scene puts the
 * file; its ground, found from the placed parts, is one more part placed
 * once (identity). Any other file as sb_mesh_load_world reads it,
 * parts->part_count 0. Free parts with sb_mesh_parts_finish. */
struct sb_mesh_parts;
enum sb_result sb_mesh_load_world_parts(const struct sb_world_params *world, const char *directory,
                                        struct sb_mesh *mesh, struct sb_mesh_parts *parts, char *path_out,
                                        size_t path_size);

#endif
