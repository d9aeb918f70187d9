/*
 * Textures as storage buffers, for kernels that filter them themselves
 * (shaders/lib/texels.glsl): every image's RGBA8 texels with its mips,
 * built on the device (texture_mips.comp), and one record an image. Both
 * programs use them: the baker's rays (baker/surfaces.h) and skyview's
 * scene, raster and traced. Bit-exact filtering a device's samplers would
 * not promise, any number of images in two bindings, and no image
 * descriptors to manage.
 */
#ifndef SB_VK_TEXELS_H
#define SB_VK_TEXELS_H

#include <stdint.h>

#include "compute.h"

/* An image as its texels: RGBA8, rows from the top. */
struct sb_texel_image {
    uint32_t width, height; /* at most 65535 */
    uint32_t wrap[2];       /* config.h's SB_SURFACE_WRAP_*, along u and v */
    bool srgb;              /* colour sRGB-encoded: filtered in linear light */
    const uint8_t *rgba;
};

struct sb_texel_set {
    /* config.h's SB_SURFACE_TEXTURES layout: one uvec4 an image (first
     * texel, width | height << 16, levels | wrap u << 8 | wrap v << 10 |
     * srgb << 12, 0); and every image's levels in turn, level 0 first */
    struct sb_buffer records, texels;
    uint32_t count;
    uint64_t texel_count;
    double gpu_ms; /* the mips' */
};

/* The levels of a width x height image down to 1 x 1. */
uint32_t sb_texel_levels(uint32_t width, uint32_t height);

/* The kernel sb_texel_set_create makes the mips with. */
struct sb_pipeline_params sb_texel_mips_kernel(void);

/* Upload `count` images (none: buffers of one element) and build their
 * mips. Refuses past 2^29 texels with their mips (SB_ERR_TOO_LARGE).
 * *set zeroed on failure. */
enum sb_result sb_texel_set_create(struct sb_vk *vk, const struct sb_texel_image *images, uint32_t count,
                                   struct sb_texel_set *set);

/* Free; accepts a zeroed set. */
void sb_texel_set_destroy(struct sb_vk *vk, struct sb_texel_set *set);

/* The mips kernel's code, for the bake keys of what samples textures. */
void sb_texel_code_hash(char out[33]);

#endif
