/*
 * The thin Vulkan layer shared by skybake and skyview: a headless instance and
 * device (no surface), one queue that does compute (and graphics where the
 * device has it), optional validation with a message counter, and debug names.
 * A context is used from one thread at a time.
 */
#ifndef SB_VK_CONTEXT_H
#define SB_VK_CONTEXT_H

#include <stdbool.h>
#include <vulkan/vulkan.h>

#include "pack.h"
#include "result.h"

struct sb_vk_params {
    /* NULL: the first discrete GPU if any, else the first device. Otherwise a
     * device index ("0", "1", ...) or a case-insensitive substring of the
     * device name ("llvmpipe", "H100"). */
    const char *device;
    /* Enable VK_LAYER_KHRONOS_validation; every warning or error it reports
     * is logged and counted (see sb_vk_validation_messages). */
    bool validate;
    /* Also rasterise: the queue must do graphics, and the device must offer
     * Vulkan 1.3 or dynamic rendering (skyview); else SB_ERR_NO_DEVICE. */
    bool graphics;
    /* Log each compute pipeline's statistics as the driver reports them
     * (VK_KHR_pipeline_executable_properties: registers, spills, workgroup
     * memory), where the device offers the extension; ignored elsewhere. */
    bool statistics;
    /* Present to a window (skyview --window): the instance extensions its
     * surface needs (glfwGetRequiredInstanceExtensions), and whether a queue
     * family of a device can present there. With can_present the device
     * enables VK_KHR_swapchain and its queue must present; else
     * SB_ERR_NO_DEVICE. NULL: headless. */
    const char *const *instance_extensions;
    uint32_t instance_extension_count;
    bool (*can_present)(VkInstance instance, VkPhysicalDevice device, uint32_t queue_family);
};

/* The parameters the environment asks for: SKYBAKE_VALIDATE and
 * SKYBAKE_PIPELINE_STATS (set and not "0"). */
struct sb_vk_params sb_vk_params_from_env(void);

struct sb_vk {
    VkInstance instance;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice physical_device;
    VkDevice device;
    VkQueue queue;
    uint32_t queue_family;
    VkCommandPool command_pool;
    VkPhysicalDeviceProperties properties;
    VkPhysicalDeviceMemoryProperties memory_properties;
    char driver_name[VK_MAX_DRIVER_NAME_SIZE];
    char driver_info[VK_MAX_DRIVER_INFO_SIZE];
    bool graphics;    /* created with sb_vk_params.graphics */
    bool depth_clamp; /* the depthClamp feature is enabled */
    bool has_timestamps;
    VkSubgroupFeatureFlags compute_subgroup_ops; /* what compute shaders' subgroups can do (0: nothing) */
    bool statistics;                             /* pipelines capture their statistics (sb_vk_params.statistics) */
    bool present; /* VK_KHR_swapchain is enabled and the queue presents (sb_vk_params.can_present) */
    double timestamp_period_ns;
    unsigned validation_messages;
    PFN_vkSetDebugUtilsObjectNameEXT set_object_name;
    struct sb_vk_cache *cache; /* the layouts and pipelines made on it (pipeline.h) */
};

/*
 * Create the context. Returns SB_ERR_NO_DEVICE (with one clear log line)
 * when no Vulkan device exists or none matches params->device, and
 * SB_ERR_VULKAN on other failures.
 */
enum sb_result sb_vk_create(const struct sb_vk_params *params, struct sb_vk **vk);

/* Wait for the device to go idle and free everything. Accepts a pointer to NULL. */
void sb_vk_destroy(struct sb_vk **vk);

/* Validation messages counted so far (0 when validation is off). */
unsigned sb_vk_validation_messages(const struct sb_vk *vk);

/*
 * One-time command buffers: begin one, record, then end it, which submits it
 * and waits for the queue. sb_vk_end_once frees the buffer on every path.
 */
enum sb_result sb_vk_begin_once(struct sb_vk *vk, VkCommandBuffer *cmd);
enum sb_result sb_vk_end_once(struct sb_vk *vk, VkCommandBuffer cmd);

/*
 * Allocate memory for `req`: of a type with every flag of `required` and,
 * where one exists, of `preferred` too; *flags (may be NULL) receives the
 * chosen type's. SB_ERR_VULKAN, naming `name`, when no type qualifies or
 * the allocation fails.
 */
enum sb_result sb_vk_allocate(struct sb_vk *vk, const VkMemoryRequirements *req, VkMemoryPropertyFlags required,
                              VkMemoryPropertyFlags preferred, const char *name, VkDeviceMemory *memory,
                              VkMemoryPropertyFlags *flags);

/* Name, driver and ids of the device, for manifests. */
void sb_vk_device_info(const struct sb_vk *vk, struct sb_device_info *info);

/* Attach a debug name to a Vulkan object (no-op without debug utils). */
void sb_vk_name(struct sb_vk *vk, VkObjectType type, uint64_t handle, const char *name);

/* "VK_ERROR_OUT_OF_DEVICE_MEMORY" and so on. */
const char *sb_vk_result_name(VkResult result);

/* Every VkResult goes through this: on failure it logs the call, the result's
 * name and file:line, sets `res` to SB_ERR_VULKAN and jumps to `cleanup`. */
#define VK(call)                                                                                                       \
    do {                                                                                                               \
        VkResult vk_result_ = (call);                                                                                  \
        if (vk_result_ != VK_SUCCESS) {                                                                                \
            sb_error("%s:%d: %s failed: %s", __FILE__, __LINE__, #call, sb_vk_result_name(vk_result_));                \
            res = SB_ERR_VULKAN;                                                                                       \
            goto cleanup;                                                                                              \
        }                                                                                                              \
    } while (0)

#endif
