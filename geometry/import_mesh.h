/*
 * What sb_mesh_import (mesh.c) and its helper program skybake-import-mesh
 * (import_mesh.c, the one process in which assimp reads a file) say to each
 * other, through formats/sandbox.h: the request, then the answer's header;
 * after a header with result 0 come material_count struct sb_mesh_material,
 * 3 x vertex_count floats (positions, world metres, three per triangle)
 * and triangle_count material indices, 2 x vertex_count floats of texture
 * coordinates when has_uvs, 4 x vertex_count of tangents when
 * has_tangents, texture_count struct sb_mesh_texture each
 * followed by its texels (4 x width x height bytes), then, for a file kept as parts
 * (mesh.h's sb_mesh_parts), part_count (first, count) pairs of uint32_t
 * and placement_count struct sb_mesh_placement. Both sides are of one build (the
 * sandbox checks), so the structs go as bytes.
 */
#ifndef SB_IMPORT_MESH_H
#define SB_IMPORT_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "scene.h"

#define SB_IMPORT_MESH_HELPER "skybake-import-mesh"
#define SB_IMPORT_MESH_MAGIC 0x534b424du /* "SKBM" */

struct sb_import_mesh_request {
    struct sb_mesh_transform transform;
    double default_albedo;
    int32_t override_count;
    struct {
        char material[64];
        double albedo[3];
    } overrides[SB_WORLD_MAX_OVERRIDES];
    int32_t keep_parts; /* sb_mesh_import_parts */
    char path[4096];
};

struct sb_import_mesh_answer {
    uint32_t magic;
    int32_t result;
    uint32_t vertex_count, triangle_count, material_count, dropped_degenerate;
    uint32_t part_count, placement_count; /* parts: then part_count (first, count) pairs and the placements */
    uint32_t has_uvs, has_tangents, texture_count;
    char message[512]; /* the first warning or error the helper logged */
};

/* The helper's task (sandbox.h's sb_sandbox_fn), in mesh.c. */
int sb_mesh_import_task(int fd, const void *request, size_t size);

#endif
