#include "window.h"

#include <stdlib.h>
#include <string.h>

#include "compute.h"
#include "log.h"

#ifndef SB_HAVE_GLFW

enum sb_result sb_window_system_init(struct sb_vk_params *params)
{
    (void)params;
    sb_error("--window: this skyview was built without GLFW (install libglfw3-dev and rebuild)");
    return SB_ERR_USAGE;
}

void sb_window_system_finish(void)
{
}

enum sb_result sb_window_create(struct sb_vk *vk, uint32_t width, uint32_t height, const char *title,
                                struct sb_window **window)
{
    (void)vk, (void)width, (void)height, (void)title;
    *window = NULL;
    return SB_ERR_USAGE;
}

void sb_window_destroy(struct sb_window **window)
{
    *window = NULL;
}

void sb_window_poll(struct sb_window *window, struct sb_window_input *input)
{
    (void)window;
    memset(input, 0, sizeof(*input));
    input->close = true;
}

enum sb_result sb_window_present(struct sb_window *window, const uint8_t *rgba, uint8_t *shot)
{
    (void)window, (void)rgba, (void)shot;
    return SB_ERR_USAGE;
}

#else

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#define MAX_IMAGES 8

struct sb_window {
    struct sb_vk *vk;
    GLFWwindow *glfw;
    uint32_t width, height;
    VkSurfaceKHR surface;
    VkSwapchainKHR swapchain;
    VkFormat format;
    bool bgra;     /* the swapchain's bytes are B, G, R, A */
    bool can_read; /* its images can be copied from (screenshots) */
    uint32_t image_count;
    VkImage images[MAX_IMAGES];
    VkSemaphore presentable[MAX_IMAGES]; /* signalled when image i's copy is done */
    VkSemaphore acquired;
    VkFence fence;
    VkCommandBuffer cmd;
    struct sb_buffer staging, readback;
    /* Input gathered by the callbacks between polls. */
    struct sb_window_input pending;
    double cursor_x, cursor_y;
    bool cursor_known;
};

static void on_glfw_error(int code, const char *message)
{
    sb_error("window system: %s (GLFW error 0x%x)", message, code);
}

static bool can_present(VkInstance instance, VkPhysicalDevice device, uint32_t queue_family)
{
    return glfwGetPhysicalDevicePresentationSupport(instance, device, queue_family) == GLFW_TRUE;
}

enum sb_result sb_window_system_init(struct sb_vk_params *params)
{
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) {
        sb_error("--window: no display to open a window on (is DISPLAY set? under CI, run with xvfb-run)");
        return SB_ERR_NO_DEVICE;
    }
    if (!glfwVulkanSupported()) {
        sb_error("--window: the window system offers no Vulkan presentation");
        glfwTerminate();
        return SB_ERR_NO_DEVICE;
    }
    uint32_t count = 0;
    const char **names = glfwGetRequiredInstanceExtensions(&count);
    params->instance_extensions = names;
    params->instance_extension_count = count;
    params->can_present = can_present;
    return SB_OK;
}

void sb_window_system_finish(void)
{
    glfwTerminate();
}

static void on_key(GLFWwindow *glfw, int key, int scancode, int action, int mods)
{
    (void)scancode, (void)mods;
    struct sb_window *w = glfwGetWindowUserPointer(glfw);
    if (action != GLFW_PRESS)
        return;
    if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9)
        w->pending.pressed_digits |= 1u << (key - GLFW_KEY_0);
    else if (key == GLFW_KEY_H || key == GLFW_KEY_F1)
        w->pending.toggle_overlay = true;
    else if (key == GLFW_KEY_P)
        w->pending.screenshot = true;
    else if (key == GLFW_KEY_ESCAPE)
        w->pending.close = true;
}

static void on_cursor(GLFWwindow *glfw, double x, double y)
{
    struct sb_window *w = glfwGetWindowUserPointer(glfw);
    bool held = glfwGetMouseButton(glfw, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS ||
                glfwGetMouseButton(glfw, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
    if (w->cursor_known && held) {
        w->pending.look_dx += x - w->cursor_x;
        w->pending.look_dy += y - w->cursor_y;
    }
    w->cursor_x = x;
    w->cursor_y = y;
    w->cursor_known = true;
}

static enum sb_result create_swapchain(struct sb_window *w)
{
    enum sb_result res = SB_OK;
    struct sb_vk *vk = w->vk;
    VkSurfaceCapabilitiesKHR caps;
    VK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(vk->physical_device, w->surface, &caps));
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
        sb_error("--window: the surface's images cannot be copied to");
        return SB_ERR_NO_DEVICE;
    }
    w->can_read = caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    uint32_t count = 0;
    VK(vkGetPhysicalDeviceSurfaceFormatsKHR(vk->physical_device, w->surface, &count, NULL));
    VkSurfaceFormatKHR formats[64];
    if (count > 64)
        count = 64;
    VK(vkGetPhysicalDeviceSurfaceFormatsKHR(vk->physical_device, w->surface, &count, formats));
    /* 8-bit formats take the frame's sRGB-encoded bytes as they are: a
     * copy does not convert, and the display reads them as sRGB. */
    static const VkFormat wanted[] = {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_UNORM,
                                      VK_FORMAT_R8G8B8A8_SRGB};
    VkSurfaceFormatKHR chosen = {VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
    for (size_t k = 0; k < sizeof(wanted) / sizeof(wanted[0]) && chosen.format == VK_FORMAT_UNDEFINED; k++)
        for (uint32_t i = 0; i < count; i++)
            if (formats[i].format == wanted[k] && formats[i].colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR)
                chosen = formats[i];
    if (chosen.format == VK_FORMAT_UNDEFINED) {
        sb_error("--window: the surface offers no 8-bit RGBA or BGRA sRGB format");
        return SB_ERR_NO_DEVICE;
    }
    w->format = chosen.format;
    w->bgra = chosen.format == VK_FORMAT_B8G8R8A8_UNORM || chosen.format == VK_FORMAT_B8G8R8A8_SRGB;
    VkExtent2D extent = caps.currentExtent;
    if (extent.width == UINT32_MAX)
        extent = (VkExtent2D){w->width, w->height};
    if (extent.width != w->width || extent.height != w->height) {
        sb_error("--window: the surface is %ux%u, not the frame's %ux%u", extent.width, extent.height, w->width,
                 w->height);
        return SB_ERR_NO_DEVICE;
    }
    uint32_t images = caps.minImageCount + 1;
    if (caps.maxImageCount && images > caps.maxImageCount)
        images = caps.maxImageCount;
    VkSwapchainKHR old = w->swapchain;
    VkSwapchainCreateInfoKHR info = {
        .sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR,
        .surface = w->surface,
        .minImageCount = images,
        .imageFormat = chosen.format,
        .imageColorSpace = chosen.colorSpace,
        .imageExtent = extent,
        .imageArrayLayers = 1,
        .imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | (w->can_read ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0),
        .imageSharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .preTransform = caps.currentTransform,
        .compositeAlpha =
            caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                : (VkCompositeAlphaFlagBitsKHR)(caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha),
        .presentMode = VK_PRESENT_MODE_FIFO_KHR, /* always offered */
        .clipped = VK_TRUE,
        .oldSwapchain = old,
    };
    VK(vkCreateSwapchainKHR(vk->device, &info, NULL, &w->swapchain));
    if (old)
        vkDestroySwapchainKHR(vk->device, old, NULL);
    w->image_count = 0;
    VK(vkGetSwapchainImagesKHR(vk->device, w->swapchain, &w->image_count, NULL));
    if (w->image_count > MAX_IMAGES) {
        sb_error("--window: the swapchain has %u images, more than %d", w->image_count, MAX_IMAGES);
        return SB_ERR_VULKAN;
    }
    VK(vkGetSwapchainImagesKHR(vk->device, w->swapchain, &w->image_count, w->images));
    VkSemaphoreCreateInfo semaphore = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    for (uint32_t i = 0; i < w->image_count; i++)
        if (!w->presentable[i])
            VK(vkCreateSemaphore(vk->device, &semaphore, NULL, &w->presentable[i]));
cleanup:
    return res;
}

enum sb_result sb_window_create(struct sb_vk *vk, uint32_t width, uint32_t height, const char *title,
                                struct sb_window **window)
{
    enum sb_result res = SB_OK;
    *window = NULL;
    struct sb_window *w = calloc(1, sizeof(*w));
    if (!w)
        return SB_ERR_NOMEM;
    w->vk = vk;
    w->width = width;
    w->height = height;
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    w->glfw = glfwCreateWindow((int)width, (int)height, title, NULL, NULL);
    if (!w->glfw) {
        sb_error("--window: cannot open a %ux%u window", width, height);
        res = SB_ERR_NO_DEVICE;
        goto cleanup;
    }
    glfwSetWindowUserPointer(w->glfw, w);
    glfwSetKeyCallback(w->glfw, on_key);
    glfwSetCursorPosCallback(w->glfw, on_cursor);
    VK(glfwCreateWindowSurface(vk->instance, w->glfw, NULL, &w->surface));
    VkBool32 supported = VK_FALSE;
    VK(vkGetPhysicalDeviceSurfaceSupportKHR(vk->physical_device, vk->queue_family, w->surface, &supported));
    if (!supported) {
        sb_error("--window: %s's queue cannot present to the window", vk->properties.deviceName);
        res = SB_ERR_NO_DEVICE;
        goto cleanup;
    }
    if ((res = create_swapchain(w)))
        goto cleanup;
    size_t bytes = (size_t)width * height * 4;
    if ((res = sb_buffer_create(vk, bytes, "window staging", &w->staging)) ||
        (res = sb_buffer_create(vk, bytes, "window screenshot", &w->readback)))
        goto cleanup;
    VkSemaphoreCreateInfo semaphore = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VK(vkCreateSemaphore(vk->device, &semaphore, NULL, &w->acquired));
    VkFenceCreateInfo fence = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK(vkCreateFence(vk->device, &fence, NULL, &w->fence));
    VkCommandBufferAllocateInfo alloc = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = vk->command_pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    VK(vkAllocateCommandBuffers(vk->device, &alloc, &w->cmd));
    *window = w;
    return SB_OK;

cleanup:
    sb_window_destroy(&w);
    return res;
}

void sb_window_destroy(struct sb_window **window)
{
    struct sb_window *w = *window;
    if (!w)
        return;
    *window = NULL;
    struct sb_vk *vk = w->vk;
    vkDeviceWaitIdle(vk->device);
    if (w->cmd)
        vkFreeCommandBuffers(vk->device, vk->command_pool, 1, &w->cmd);
    if (w->fence)
        vkDestroyFence(vk->device, w->fence, NULL);
    if (w->acquired)
        vkDestroySemaphore(vk->device, w->acquired, NULL);
    for (uint32_t i = 0; i < MAX_IMAGES; i++)
        if (w->presentable[i])
            vkDestroySemaphore(vk->device, w->presentable[i], NULL);
    sb_buffer_destroy(vk, &w->staging);
    sb_buffer_destroy(vk, &w->readback);
    if (w->swapchain)
        vkDestroySwapchainKHR(vk->device, w->swapchain, NULL);
    if (w->surface)
        vkDestroySurfaceKHR(vk->instance, w->surface, NULL);
    if (w->glfw)
        glfwDestroyWindow(w->glfw);
    free(w);
}

void sb_window_poll(struct sb_window *w, struct sb_window_input *input)
{
    glfwPollEvents();
    *input = w->pending;
    memset(&w->pending, 0, sizeof(w->pending));
    GLFWwindow *g = w->glfw;
    input->close = input->close || glfwWindowShouldClose(g);
    input->forward = glfwGetKey(g, GLFW_KEY_W) == GLFW_PRESS;
    input->back = glfwGetKey(g, GLFW_KEY_S) == GLFW_PRESS;
    input->left = glfwGetKey(g, GLFW_KEY_A) == GLFW_PRESS;
    input->right = glfwGetKey(g, GLFW_KEY_D) == GLFW_PRESS;
    input->up = glfwGetKey(g, GLFW_KEY_E) == GLFW_PRESS;
    input->down = glfwGetKey(g, GLFW_KEY_Q) == GLFW_PRESS;
    input->fast = glfwGetKey(g, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS || glfwGetKey(g, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    input->sun_left = glfwGetKey(g, GLFW_KEY_LEFT) == GLFW_PRESS;
    input->sun_right = glfwGetKey(g, GLFW_KEY_RIGHT) == GLFW_PRESS;
    input->sun_up = glfwGetKey(g, GLFW_KEY_UP) == GLFW_PRESS;
    input->sun_down = glfwGetKey(g, GLFW_KEY_DOWN) == GLFW_PRESS;
}

static void image_barrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to,
                          VkAccessFlags src_access, VkAccessFlags dst_access)
{
    VkImageMemoryBarrier b = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
        .srcAccessMask = src_access,
        .dstAccessMask = dst_access,
        .oldLayout = from,
        .newLayout = to,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = image,
        .subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1},
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                         VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, NULL, 0, NULL, 1,
                         &b);
}

/* RGBA to the swapchain's byte order, and back (the same swap). */
static void copy_pixels(uint8_t *dst, const uint8_t *src, size_t pixels, bool swap)
{
    if (!swap) {
        memcpy(dst, src, pixels * 4);
        return;
    }
    for (size_t i = 0; i < pixels; i++) {
        dst[4 * i + 0] = src[4 * i + 2];
        dst[4 * i + 1] = src[4 * i + 1];
        dst[4 * i + 2] = src[4 * i + 0];
        dst[4 * i + 3] = src[4 * i + 3];
    }
}

enum sb_result sb_window_present(struct sb_window *w, const uint8_t *rgba, uint8_t *shot)
{
    enum sb_result res = SB_OK;
    struct sb_vk *vk = w->vk;
    if (shot && !w->can_read) {
        sb_error("--window: the swapchain's images cannot be read back for a screenshot");
        return SB_ERR_USAGE;
    }
    uint32_t index;
    VkResult acquired =
        vkAcquireNextImageKHR(vk->device, w->swapchain, UINT64_MAX, w->acquired, VK_NULL_HANDLE, &index);
    if (acquired == VK_ERROR_OUT_OF_DATE_KHR)
        return create_swapchain(w); /* this frame is dropped; the next one goes to the new chain */
    if (acquired != VK_SUBOPTIMAL_KHR)
        VK(acquired);
    size_t pixels = (size_t)w->width * w->height;
    copy_pixels(w->staging.mapped, rgba, pixels, w->bgra);

    VkImage image = w->images[index];
    VK(vkResetCommandBuffer(w->cmd, 0));
    VkCommandBufferBeginInfo begin = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    VK(vkBeginCommandBuffer(w->cmd, &begin));
    image_barrier(w->cmd, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                  VK_ACCESS_TRANSFER_WRITE_BIT);
    VkBufferImageCopy region = {
        .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
        .imageExtent = {w->width, w->height, 1},
    };
    vkCmdCopyBufferToImage(w->cmd, w->staging.buffer, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    VkImageLayout now = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    if (shot) {
        image_barrier(w->cmd, image, now, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_ACCESS_TRANSFER_READ_BIT);
        now = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        vkCmdCopyImageToBuffer(w->cmd, image, now, w->readback.buffer, 1, &region);
        VkMemoryBarrier to_host = {
            .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
            .srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT,
            .dstAccessMask = VK_ACCESS_HOST_READ_BIT,
        };
        vkCmdPipelineBarrier(w->cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                             NULL, 0, NULL);
    }
    image_barrier(w->cmd, image, now, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                  shot ? VK_ACCESS_TRANSFER_READ_BIT : VK_ACCESS_TRANSFER_WRITE_BIT, 0);
    VK(vkEndCommandBuffer(w->cmd));
    VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo submit = {
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
        .waitSemaphoreCount = 1,
        .pWaitSemaphores = &w->acquired,
        .pWaitDstStageMask = &wait_stage,
        .commandBufferCount = 1,
        .pCommandBuffers = &w->cmd,
        .signalSemaphoreCount = 1,
        .pSignalSemaphores = &w->presentable[index],
    };
    VK(vkResetFences(vk->device, 1, &w->fence));
    VK(vkQueueSubmit(vk->queue, 1, &submit, w->fence));
    VkPresentInfoKHR present = {
        .sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR,
        .waitSemaphoreCount = 1,
        .pWaitSemaphores = &w->presentable[index],
        .swapchainCount = 1,
        .pSwapchains = &w->swapchain,
        .pImageIndices = &index,
    };
    VkResult presented = vkQueuePresentKHR(vk->queue, &present);
    /* The staging buffer is written again next frame: wait for the copy. */
    VK(vkWaitForFences(vk->device, 1, &w->fence, VK_TRUE, UINT64_MAX));
    if (presented == VK_ERROR_OUT_OF_DATE_KHR || presented == VK_SUBOPTIMAL_KHR)
        res = create_swapchain(w);
    else
        VK(presented);
    if (shot)
        copy_pixels(shot, w->readback.mapped, pixels, w->bgra);
cleanup:
    return res;
}

#endif
