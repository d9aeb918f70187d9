#include "texture.h"

#include <string.h>

#include "compute.h"
#include "log.h"

static bool is_depth(VkFormat f)
{
    return f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D16_UNORM || f == VK_FORMAT_X8_D24_UNORM_PACK32;
}

enum sb_result sb_texture_create(struct sb_vk *vk, const struct sb_texture_params *params, struct sb_texture *t)
{
    enum sb_result res = SB_OK;
    memset(t, 0, sizeof(*t));
    t->width = params->width;
    t->height = params->height;
    t->depth = params->depth ? params->depth : 1;
    t->layers = params->layers ? params->layers : 1;
    t->mips = params->mips ? params->mips : 1;
    t->format = params->format;
    t->aspect = is_depth(params->format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    if (t->layers > SB_TEXTURE_MAX_SUBVIEWS || t->mips > SB_TEXTURE_MAX_SUBVIEWS) {
        sb_error("%s: %u layers and %u mips; at most %d", params->name, t->layers, t->mips, SB_TEXTURE_MAX_SUBVIEWS);
        return SB_ERR_OUT_OF_RANGE;
    }
    VkImageCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
        .imageType = t->depth > 1 ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D,
        .format = params->format,
        .extent = {t->width, t->height, t->depth},
        .mipLevels = t->mips,
        .arrayLayers = t->layers,
        .samples = VK_SAMPLE_COUNT_1_BIT,
        .tiling = VK_IMAGE_TILING_OPTIMAL,
        .usage = params->usage,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
    };
    VK(vkCreateImage(vk->device, &info, NULL, &t->image));
    sb_vk_name(vk, VK_OBJECT_TYPE_IMAGE, (uint64_t)t->image, params->name);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(vk->device, t->image, &req);
    if ((res = sb_vk_allocate(vk, &req, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, params->name, &t->memory, NULL)))
        goto cleanup;
    VK(vkBindImageMemory(vk->device, t->image, t->memory, 0));

    VkImageViewType whole_type = t->depth > 1                     ? VK_IMAGE_VIEW_TYPE_3D
                                 : t->layers > 1 || params->array ? VK_IMAGE_VIEW_TYPE_2D_ARRAY
                                                                  : VK_IMAGE_VIEW_TYPE_2D;
    VkImageViewCreateInfo view = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
        .image = t->image,
        .viewType = whole_type,
        .format = params->format,
        .subresourceRange = {t->aspect, 0, t->mips, 0, t->layers},
    };
    VK(vkCreateImageView(vk->device, &view, NULL, &t->view));
    /* Per layer of an array, or per mip level of anything else. */
    t->subview_count = t->layers > 1 ? t->layers : (t->mips > 1 ? t->mips : 0);
    for (uint32_t i = 0; i < t->subview_count; i++) {
        view.viewType = t->depth > 1 ? VK_IMAGE_VIEW_TYPE_3D : VK_IMAGE_VIEW_TYPE_2D;
        view.subresourceRange = t->layers > 1 ? (VkImageSubresourceRange){t->aspect, 0, t->mips, i, 1}
                                              : (VkImageSubresourceRange){t->aspect, i, 1, 0, 1};
        VK(vkCreateImageView(vk->device, &view, NULL, &t->subviews[i]));
    }

    VkCommandBuffer cmd;
    if ((res = sb_vk_begin_once(vk, &cmd)))
        goto cleanup;
    sb_texture_barrier(cmd, t, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    if ((res = sb_vk_end_once(vk, cmd)))
        goto cleanup;
    return SB_OK;

cleanup:
    sb_texture_destroy(vk, t);
    return res;
}

void sb_texture_barrier(VkCommandBuffer cmd, const struct sb_texture *t, VkImageLayout from, VkImageLayout to)
{
    VkImageMemoryBarrier b = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT,
        .oldLayout = from,
        .newLayout = to,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = t->image,
        .subresourceRange = {t->aspect, 0, t->mips, 0, t->layers},
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, NULL, 0,
                         NULL, 1, &b);
}

enum sb_result sb_texture_upload(struct sb_vk *vk, const struct sb_texture *t, const void *data, size_t bytes,
                                 size_t texel_bytes)
{
    if (bytes != (size_t)t->width * t->height * t->depth * t->layers * texel_bytes || !bytes) {
        sb_error("texture upload: %zu bytes for %u x %u x %u x %u texels of %zu bytes", bytes, t->width, t->height,
                 t->depth, t->layers, texel_bytes);
        return SB_ERR_USAGE;
    }
    struct sb_buffer staging;
    enum sb_result res = sb_buffer_create(vk, bytes, "texture upload", &staging);
    if (res)
        return res;
    memcpy(staging.mapped, data, bytes);
    VkCommandBuffer cmd;
    if (!(res = sb_vk_begin_once(vk, &cmd))) {
        VkBufferImageCopy region = {
            .imageSubresource = {t->aspect, 0, 0, t->layers},
            .imageExtent = {t->width, t->height, t->depth},
        };
        sb_texture_barrier(cmd, t, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        vkCmdCopyBufferToImage(cmd, staging.buffer, t->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        sb_texture_barrier(cmd, t, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
        res = sb_vk_end_once(vk, cmd);
    }
    sb_buffer_destroy(vk, &staging);
    return res;
}

void sb_texture_destroy(struct sb_vk *vk, struct sb_texture *t)
{
    for (uint32_t i = 0; i < t->subview_count; i++)
        if (t->subviews[i])
            vkDestroyImageView(vk->device, t->subviews[i], NULL);
    if (t->view)
        vkDestroyImageView(vk->device, t->view, NULL);
    if (t->image)
        vkDestroyImage(vk->device, t->image, NULL);
    if (t->memory)
        vkFreeMemory(vk->device, t->memory, NULL);
    memset(t, 0, sizeof(*t));
}
