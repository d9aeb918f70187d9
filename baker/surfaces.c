#include "surfaces.h"

#include <string.h>

#include "config.h"
#include "log.h"
#include "texture_mips.spv.h"

_Static_assert(SB_SURFACE_WRAP_REPEAT == SB_TEXTURE_REPEAT && SB_SURFACE_WRAP_CLAMP == SB_TEXTURE_CLAMP &&
                   SB_SURFACE_WRAP_MIRROR == SB_TEXTURE_MIRROR,
               "surface.glsl reads texture.h's wrap modes");

/* surface.glsl's material record */
struct surface_material {
    float albedo[3];
    uint32_t base_texture; /* + 1; 0: none */
};

static const char *const buffer_names[SB_SURFACE_BINDING_COUNT] = {"materials", "uvs", "textures", "texels"};

void sb_surfaces_destroy(struct sb_vk *vk, struct sb_surfaces *surfaces)
{
    for (int b = 0; b < SB_SURFACE_BINDING_COUNT; b++)
        sb_buffer_destroy(vk, &surfaces->buffers[b]);
    memset(surfaces, 0, sizeof(*surfaces));
}

void sb_surfaces_code_hash(char out[33])
{
    sb_hash_bytes(sb_spv_texture_mips, sizeof(sb_spv_texture_mips), out);
}

/* Every level below the first, one dispatch a level over all textures. */
static enum sb_result make_mips(struct sb_vk *vk, struct sb_surfaces *s, uint32_t max_levels, uint32_t max_side)
{
    struct sb_pipeline pipeline = {0};
    const struct sb_pipeline_params pp = {
        .spirv = sb_spv_texture_mips,
        .spirv_size = sizeof(sb_spv_texture_mips),
        .binding_count = SB_TEXTURE_MIPS_BINDING_COUNT,
        .push_size = sizeof(struct sb_texture_mips_push),
        .name = "texture mips",
    };
    enum sb_result res = sb_pipeline_create(vk, &pp, &pipeline);
    if (res)
        return res;
    const struct sb_buffer *bindings[SB_TEXTURE_MIPS_BINDING_COUNT] = {
        [SB_TEXTURE_MIPS_BINDING_TEXTURES] = &s->buffers[SB_SURFACE_TEXTURES],
        [SB_TEXTURE_MIPS_BINDING_TEXELS] = &s->buffers[SB_SURFACE_TEXELS],
    };
    sb_pipeline_bind(vk, &pipeline, bindings);
    for (uint32_t level = 1; level < max_levels && !res; level++) {
        struct sb_texture_mips_push pc = {.level = level, .texture_count = s->texture_count};
        uint32_t side = max_side >> level ? max_side >> level : 1;
        uint32_t groups = (side + SB_WORKGROUP_X - 1) / SB_WORKGROUP_X;
        double ms = 0;
        res = sb_dispatch(vk, &pipeline, &pc, groups, groups, s->texture_count, &ms);
        s->gpu_ms += ms;
    }
    sb_pipeline_destroy(vk, &pipeline);
    return res;
}

enum sb_result sb_surfaces_create(struct sb_vk *vk, const struct sb_mesh *meshes, uint32_t mesh_count,
                                  struct sb_surfaces *s)
{
    memset(s, 0, sizeof(*s));
    uint64_t triangles = 0, texels = 0;
    uint32_t max_levels = 1, max_side = 1;
    for (uint32_t m = 0; m < mesh_count; m++) {
        s->material_count += meshes[m].material_count;
        s->texture_count += meshes[m].texture_count;
        triangles += meshes[m].triangle_count;
        for (uint32_t k = 0; k < meshes[m].texture_count; k++) {
            const struct sb_mesh_texture *t = &meshes[m].texture_list[k];
            uint32_t levels = sb_texture_levels(t->width, t->height), w = t->width, h = t->height;
            for (uint32_t l = 0; l < levels; l++, w = w > 1 ? w >> 1 : 1, h = h > 1 ? h >> 1 : 1)
                texels += (uint64_t)w * h;
            max_levels = levels > max_levels ? levels : max_levels;
            max_side = t->width > max_side ? t->width : max_side;
            max_side = t->height > max_side ? t->height : max_side;
        }
    }
    if (texels >= (1ull << 31) / sizeof(uint32_t)) {
        sb_error("the world's textures hold %llu texels with their mips; at most 2^29",
                 (unsigned long long)texels);
        return SB_ERR_TOO_LARGE;
    }
    s->texel_count = texels;
    bool textured = s->texture_count > 0;
    VkDeviceSize sizes[SB_SURFACE_BINDING_COUNT] = {
        [SB_SURFACE_MATERIALS] = (s->material_count ? s->material_count : 1) * sizeof(struct surface_material),
        [SB_SURFACE_UVS] = (textured ? triangles : 1) * 6 * sizeof(float),
        [SB_SURFACE_TEXTURES] = (textured ? s->texture_count : 1) * 4 * sizeof(uint32_t),
        [SB_SURFACE_TEXELS] = (textured ? texels : 1) * sizeof(uint32_t),
    };
    enum sb_result res = SB_OK;
    for (int b = 0; b < SB_SURFACE_BINDING_COUNT && !res; b++)
        res = sb_buffer_create(vk, sizes[b], buffer_names[b], &s->buffers[b]);
    if (res) {
        sb_surfaces_destroy(vk, s);
        return res;
    }
    struct surface_material *materials = s->buffers[SB_SURFACE_MATERIALS].mapped;
    float *uvs = s->buffers[SB_SURFACE_UVS].mapped;
    uint32_t(*records)[4] = s->buffers[SB_SURFACE_TEXTURES].mapped;
    uint8_t *texel_bytes = s->buffers[SB_SURFACE_TEXELS].mapped;
    uint32_t material = 0, texture = 0;
    uint64_t first_texel = 0, triangle = 0;
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
        for (uint32_t k = 0; k < mesh->texture_count; k++, texture++) {
            const struct sb_mesh_texture *t = &mesh->texture_list[k];
            uint32_t levels = sb_texture_levels(t->width, t->height);
            records[texture][0] = (uint32_t)first_texel;
            records[texture][1] = t->width | t->height << 16;
            records[texture][2] = levels | t->wrap[0] << 8 | t->wrap[1] << 10 | t->srgb << 12;
            records[texture][3] = 0;
            memcpy(texel_bytes + 4 * first_texel, t->rgba, sb_texture_bytes(t));
            for (uint32_t l = 0, w = t->width, h = t->height; l < levels;
                 l++, w = w > 1 ? w >> 1 : 1, h = h > 1 ? h >> 1 : 1)
                first_texel += (uint64_t)w * h;
        }
    }
    if (textured && max_levels > 1)
        res = make_mips(vk, s, max_levels, max_side);
    if (res)
        sb_surfaces_destroy(vk, s);
    return res;
}
