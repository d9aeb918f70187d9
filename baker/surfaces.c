#include "surfaces.h"

#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "log.h"
#include "raycast.h"

_Static_assert(SB_SURFACE_WRAP_REPEAT == SB_TEXTURE_REPEAT && SB_SURFACE_WRAP_CLAMP == SB_TEXTURE_CLAMP &&
                   SB_SURFACE_WRAP_MIRROR == SB_TEXTURE_MIRROR,
               "surface.glsl reads mesh_texture.h's wrap modes");

/* surface.glsl's material record */
struct surface_material {
    float albedo[3];
    uint32_t base_texture; /* + 1; 0: none */
};

void sb_surfaces_destroy(struct sb_vk *vk, struct sb_surfaces *surfaces)
{
    sb_buffer_destroy(vk, &surfaces->materials);
    sb_buffer_destroy(vk, &surfaces->uvs);
    sb_texel_set_destroy(vk, &surfaces->textures);
    memset(surfaces, 0, sizeof(*surfaces));
}

void sb_surfaces_bindings(const struct sb_surfaces *s, const struct sb_buffer *out[SB_SURFACE_BINDING_COUNT])
{
    out[SB_SURFACE_MATERIALS] = &s->materials;
    out[SB_SURFACE_UVS] = &s->uvs;
    out[SB_SURFACE_TEXTURES] = &s->textures.records;
    out[SB_SURFACE_TEXELS] = &s->textures.texels;
}

void sb_surfaces_code_hash(char out[33])
{
    sb_texel_code_hash(out);
}

enum sb_result sb_surfaces_create(struct sb_vk *vk, const struct sb_mesh *meshes, uint32_t mesh_count,
                                  struct sb_surfaces *s)
{
    memset(s, 0, sizeof(*s));
    uint64_t triangles = 0;
    uint32_t texture_count = 0;
    for (uint32_t m = 0; m < mesh_count; m++) {
        s->material_count += meshes[m].material_count;
        texture_count += meshes[m].texture_count;
        triangles += meshes[m].triangle_count;
    }
    struct sb_texel_image *images = calloc(texture_count ? texture_count : 1, sizeof(*images));
    if (!images)
        return SB_ERR_NOMEM;
    for (uint32_t m = 0, i = 0; m < mesh_count; m++)
        for (uint32_t k = 0; k < meshes[m].texture_count; k++, i++) {
            const struct sb_mesh_texture *t = &meshes[m].texture_list[k];
            images[i] = (struct sb_texel_image){.width = t->width, .height = t->height, .wrap = {t->wrap[0], t->wrap[1]},
                                                .srgb = t->srgb != 0, .rgba = t->rgba};
        }
    enum sb_result res = sb_texel_set_create(vk, images, texture_count, &s->textures);
    free(images);
    bool textured = texture_count > 0;
    if (!res)
        res = sb_buffer_create(vk, (s->material_count ? s->material_count : 1) * sizeof(struct surface_material),
                               "materials", &s->materials);
    if (!res)
        res = sb_buffer_create(vk, (textured ? triangles : 1) * 6 * sizeof(float), "texture coordinates", &s->uvs);
    if (res) {
        sb_surfaces_destroy(vk, s);
        return res;
    }
    struct surface_material *materials = s->materials.mapped;
    float *uvs = s->uvs.mapped;
    uint32_t material = 0, texture = 0;
    uint64_t triangle = 0;
    for (uint32_t m = 0; m < mesh_count; m++) {
        const struct sb_mesh *mesh = &meshes[m];
        for (uint32_t k = 0; k < mesh->material_count; k++, material++) {
            const struct sb_mesh_material *from = &mesh->material_list[k];
            memcpy(materials[material].albedo, from->albedo, sizeof(from->albedo));
            int32_t base = from->textures[SB_TEXTURE_BASE_COLOR];
            materials[material].base_texture = base >= 0 && mesh->uvs ? texture + (uint32_t)base + 1 : 0;
        }
        for (uint32_t t = 0; textured && mesh->uvs && t < mesh->triangle_count; t++)
            for (int v = 0; v < 3; v++)
                memcpy(&uvs[6 * (triangle + t) + 2 * v], &mesh->uvs[2 * (size_t)mesh->indices[3 * (size_t)t + v]],
                       2 * sizeof(float));
        triangle += mesh->triangle_count;
        texture += mesh->texture_count;
    }
    return SB_OK;
}

uint32_t sb_surfaces_level_kernels(const struct sb_level *level, bool surfaces, struct sb_pipeline_params out[2])
{
    uint32_t n = 0;
    out[n++] = sb_raycast_kernel(level->instance_count > 0);
    bool textured = false;
    if (!surfaces)
        return n;
    for (uint32_t m = 0; m < level->mesh_count && !textured; m++)
        textured = level->meshes[m].texture_count > 0;
    if (textured)
        out[n++] = sb_texel_mips_kernel();
    return n;
}
