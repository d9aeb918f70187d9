/*
 * The world skyview lights: a square ground plane at y = 0 and boxes and
 * pillars on it, each with a PBR material, read from a JSON file (schema in
 * docs/skyview.md; data/worlds/test.json is the default) and turned into
 * one triangle list.
 */
#ifndef SB_RUNTIME_WORLD_H
#define SB_RUNTIME_WORLD_H

#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "result.h"

#define SB_WORLD_MAX_OBJECTS 256

struct sb_material {
    double albedo[3]; /* linear base colour, [0, 1] */
    double roughness; /* perceptual, [0, 1] */
    double metallic;  /* [0, 1] */
};

struct sb_world_box {
    double center_m[3];
    double size_m[3];
    struct sb_material material;
};

struct sb_world_pillar {
    double base_m[3]; /* centre of the bottom face */
    double radius_m;
    double height_m;
    int sides; /* 3 to 64 */
    struct sb_material material;
};

struct sb_world {
    double ground_size_m; /* the ground plane is this wide, centred on the origin */
    struct sb_material ground;
    int box_count, pillar_count;
    struct sb_world_box boxes[SB_WORLD_MAX_OBJECTS];
    struct sb_world_pillar pillars[SB_WORLD_MAX_OBJECTS];
    struct sb_vertex_gpu *vertices; /* owned: vertex_count, a triangle list */
    uint32_t vertex_count;
    uint32_t caster_first_vertex; /* the ground comes first: it receives shadows but casts none */
};

/* Read and check a world file, then build its triangles. On failure the
 * world is zeroed and the message names the file, the field and the reason. */
enum sb_result sb_world_load(const char *path, struct sb_world *world);
/* The same from a world file's text; source names it in messages. */
enum sb_result sb_world_parse(const char *json, size_t size, const char *source, struct sb_world *world);
/* Free the triangles; accepts a zeroed world. */
void sb_world_finish(struct sb_world *world);

#endif
