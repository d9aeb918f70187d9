/*
 * What the baker's rays see of the surfaces they hit (shaders/lib/
 * surface.glsl): each material's albedo and base-colour texture, each
 * triangle's texture coordinates, and every texture with its mips, built
 * on the device (texture_mips.comp) from the texels the mesh import
 * decoded (geometry/mesh_texture.h). The bounce (sky_bounce.h) and the
 * reflection capture (reflection.h) bind them.
 */
#ifndef SB_BAKER_SURFACES_H
#define SB_BAKER_SURFACES_H

#include <stdint.h>

#include "compute.h"
#include "level.h"
#include "mesh.h"
#include "texels.h"

struct sb_surfaces {
    struct sb_buffer materials, uvs; /* config.h's SB_SURFACE_MATERIALS and SB_SURFACE_UVS */
    struct sb_texel_set textures;    /* SB_SURFACE_TEXTURES and SB_SURFACE_TEXELS (vulkan/texels.h) */
    uint32_t material_count;
};

/* The four buffers in config.h's SB_SURFACE_* order, for a kernel's bindings. */
void sb_surfaces_bindings(const struct sb_surfaces *surfaces, const struct sb_buffer *out[SB_SURFACE_BINDING_COUNT]);

/*
 * The surfaces of `meshes` taken in turn, as a BVH over them numbers their
 * triangles and materials (bvh.h: one mesh, or a level's meshes). Every
 * texture is uploaded with its mips (the kernels read the base colour's);
 * a world without textures costs buffers of one element. *surfaces zeroed on failure.
 */
enum sb_result sb_surfaces_create(struct sb_vk *vk, const struct sb_mesh *meshes, uint32_t mesh_count,
                                  struct sb_surfaces *surfaces);

/* A level's (sb_level's meshes). */
static inline enum sb_result sb_surfaces_create_level(struct sb_vk *vk, const struct sb_level *level,
                                                      struct sb_surfaces *surfaces)
{
    return sb_surfaces_create(vk, level->meshes, level->mesh_count, surfaces);
}

/* The kernels a bake against `level` makes for its rays and, with
 * `surfaces`, its surfaces: the raycaster's (sb_raycaster_create) and, for
 * a level with textures, the mips'; returns their count (at most 2). */
uint32_t sb_surfaces_level_kernels(const struct sb_level *level, bool surfaces, struct sb_pipeline_params out[2]);

/* Free; accepts a zeroed one. */
void sb_surfaces_destroy(struct sb_vk *vk, struct sb_surfaces *surfaces);

/* The mips kernel's code, for the bake keys of what samples textures. */
void sb_surfaces_code_hash(char out[33]);

#endif
