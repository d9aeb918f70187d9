/*
 * Images on the device ("textures", to keep them apart from formats/'s CPU
 * images): 2D, 2D arrays, 3D, with mip levels, each with a view of the whole
 * and one view per layer or per mip level. A texture starts in
 * VK_IMAGE_LAYOUT_GENERAL, where storage and sampled use need only memory
 * barriers between passes; users move attachments to the optimal layouts
 * around rendering (depth compression is worth it) and back.
 */
#ifndef SB_VK_TEXTURE_H
#define SB_VK_TEXTURE_H

#include <stdbool.h>
#include <stdint.h>

#include "context.h"

#define SB_TEXTURE_MAX_SUBVIEWS 16

struct sb_texture_params {
    uint32_t width, height;
    uint32_t depth;  /* 0 or 1: 2D; more: 3D */
    uint32_t layers; /* 0 or 1: one layer; more: a 2D array */
    bool array;      /* a 2D array however many layers (a shader's sampler2DArray) */
    uint32_t mips;   /* 0: 1 */
    VkFormat format;
    VkImageUsageFlags usage;
    const char *name;
};

struct sb_texture {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;                              /* everything */
    VkImageView subviews[SB_TEXTURE_MAX_SUBVIEWS]; /* per layer (arrays) or per mip level */
    uint32_t subview_count;
    VkFormat format;
    VkImageAspectFlags aspect;
    uint32_t width, height, depth, layers, mips;
};

/* Create a texture in device-local memory, in the general layout, its
 * contents undefined. Returns SB_ERR_OUT_OF_RANGE for more than
 * SB_TEXTURE_MAX_SUBVIEWS layers or mips, SB_ERR_VULKAN on other failures. */
enum sb_result sb_texture_create(struct sb_vk *vk, const struct sb_texture_params *params, struct sb_texture *texture);
/* Record a move of the whole texture from one layout to another, after every
 * earlier command's writes and before every later command (a full barrier:
 * skyview's passes depend on each other in sequence anyway). */
void sb_texture_barrier(VkCommandBuffer cmd, const struct sb_texture *t, VkImageLayout from, VkImageLayout to);
/* Fill mip level 0 of every layer of a colour texture, in the general
 * layout, from `bytes` of tightly packed texels (layer by layer, then slice
 * by slice, row by row), through a staging buffer; waits for the copy.
 * Call it outside other recording. SB_ERR_USAGE when `bytes` is not the
 * level's size in `texel_bytes` a texel. */
enum sb_result sb_texture_upload(struct sb_vk *vk, const struct sb_texture *texture, const void *data, size_t bytes,
                                 size_t texel_bytes);
/* Free a texture; accepts a zeroed one. */
void sb_texture_destroy(struct sb_vk *vk, struct sb_texture *texture);

#endif
