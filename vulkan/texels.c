#include "texels.h"

#include <string.h>

#include "config.h"
#include "log.h"
#include "texture_mips.spv.h"

uint32_t sb_texel_levels(uint32_t width, uint32_t height)
{
    uint32_t levels = 1;
    for (uint32_t side = width > height ? width : height; side > 1; side >>= 1)
        levels++;
    return levels;
}

void sb_texel_set_destroy(struct sb_vk *vk, struct sb_texel_set *set)
{
    sb_buffer_destroy(vk, &set->records);
    sb_buffer_destroy(vk, &set->texels);
    memset(set, 0, sizeof(*set));
}

void sb_texel_code_hash(char out[33])
{
    sb_hash_bytes(sb_spv_texture_mips, sizeof(sb_spv_texture_mips), out);
}

static uint64_t chain_texels(uint32_t w, uint32_t h)
{
    uint64_t n = 0;
    for (uint32_t l = 0, levels = sb_texel_levels(w, h); l < levels; l++, w = w > 1 ? w >> 1 : 1, h = h > 1 ? h >> 1 : 1)
        n += (uint64_t)w * h;
    return n;
}

struct sb_pipeline_params sb_texel_mips_kernel(void)
{
    return (struct sb_pipeline_params){
        .spirv = sb_spv_texture_mips,
        .spirv_size = sizeof(sb_spv_texture_mips),
        .binding_count = SB_TEXTURE_MIPS_BINDING_COUNT,
        .push_size = sizeof(struct sb_texture_mips_push),
        .name = "texture mips",
    };
}

/* Every level below the first, one dispatch a level over all images. */
static enum sb_result make_mips(struct sb_vk *vk, struct sb_texel_set *s, uint32_t max_levels, uint32_t max_side)
{
    struct sb_pipeline pipeline = {0};
    const struct sb_pipeline_params pp = sb_texel_mips_kernel();
    enum sb_result res = sb_pipeline_create(vk, &pp, &pipeline);
    if (res)
        return res;
    const struct sb_buffer *bindings[SB_TEXTURE_MIPS_BINDING_COUNT] = {
        [SB_TEXTURE_MIPS_BINDING_TEXTURES] = &s->records,
        [SB_TEXTURE_MIPS_BINDING_TEXELS] = &s->texels,
    };
    sb_pipeline_bind(vk, &pipeline, bindings);
    for (uint32_t level = 1; level < max_levels && !res; level++) {
        struct sb_texture_mips_push pc = {.level = level, .texture_count = s->count};
        uint32_t side = max_side >> level ? max_side >> level : 1;
        uint32_t groups = (side + SB_WORKGROUP_X - 1) / SB_WORKGROUP_X;
        double ms = 0;
        res = sb_dispatch(vk, &pipeline, &pc, groups, groups, s->count, &ms);
        s->gpu_ms += ms;
    }
    sb_pipeline_destroy(vk, &pipeline);
    return res;
}

enum sb_result sb_texel_set_create(struct sb_vk *vk, const struct sb_texel_image *images, uint32_t count,
                                   struct sb_texel_set *s)
{
    memset(s, 0, sizeof(*s));
    uint32_t max_levels = 1, max_side = 1;
    for (uint32_t i = 0; i < count; i++) {
        const struct sb_texel_image *im = &images[i];
        if (!im->width || !im->height || im->width > 0xffff || im->height > 0xffff || im->wrap[0] > 2 ||
            im->wrap[1] > 2) {
            sb_error("texture %u: %u x %u texels, wrap %u, %u: not an image the kernels read", i, im->width,
                     im->height, im->wrap[0], im->wrap[1]);
            return SB_ERR_OUT_OF_RANGE;
        }
        s->texel_count += chain_texels(im->width, im->height);
        uint32_t levels = sb_texel_levels(im->width, im->height);
        max_levels = levels > max_levels ? levels : max_levels;
        max_side = im->width > max_side ? im->width : max_side;
        max_side = im->height > max_side ? im->height : max_side;
    }
    if (s->texel_count >= (1ull << 31) / sizeof(uint32_t)) {
        sb_error("%u textures of %llu texels with their mips; at most 2^29", count,
                 (unsigned long long)s->texel_count);
        return SB_ERR_TOO_LARGE;
    }
    enum sb_result res = sb_buffer_create(vk, (count ? count : 1) * 4 * sizeof(uint32_t), "texture records",
                                          &s->records);
    if (!res)
        res = sb_buffer_create(vk, (count ? s->texel_count : 1) * sizeof(uint32_t), "texels", &s->texels);
    if (res) {
        sb_texel_set_destroy(vk, s);
        return res;
    }
    s->count = count;
    uint32_t(*records)[4] = s->records.mapped;
    uint8_t *texels = s->texels.mapped;
    uint64_t first = 0;
    for (uint32_t i = 0; i < count; i++) {
        const struct sb_texel_image *im = &images[i];
        records[i][0] = (uint32_t)first;
        records[i][1] = im->width | im->height << 16;
        records[i][2] = sb_texel_levels(im->width, im->height) | im->wrap[0] << 8 | im->wrap[1] << 10 |
                        (uint32_t)im->srgb << 12;
        records[i][3] = 0;
        memcpy(texels + 4 * first, im->rgba, (size_t)4 * im->width * im->height);
        first += chain_texels(im->width, im->height);
    }
    if (count && max_levels > 1)
        res = make_mips(vk, s, max_levels, max_side);
    if (res)
        sb_texel_set_destroy(vk, s);
    return res;
}
