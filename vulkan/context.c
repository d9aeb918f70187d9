#include "context.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compute.h"
#include "log.h"
#include "pipeline.h"

#define VALIDATION_LAYER "VK_LAYER_KHRONOS_validation"

const char *sb_vk_result_name(VkResult r)
{
    switch (r) {
#define CASE(x)                                                                                                        \
    case x:                                                                                                            \
        return #x
        CASE(VK_SUCCESS);
        CASE(VK_NOT_READY);
        CASE(VK_TIMEOUT);
        CASE(VK_INCOMPLETE);
        CASE(VK_ERROR_OUT_OF_HOST_MEMORY);
        CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY);
        CASE(VK_ERROR_INITIALIZATION_FAILED);
        CASE(VK_ERROR_DEVICE_LOST);
        CASE(VK_ERROR_MEMORY_MAP_FAILED);
        CASE(VK_ERROR_LAYER_NOT_PRESENT);
        CASE(VK_ERROR_EXTENSION_NOT_PRESENT);
        CASE(VK_ERROR_FEATURE_NOT_PRESENT);
        CASE(VK_ERROR_INCOMPATIBLE_DRIVER);
        CASE(VK_ERROR_TOO_MANY_OBJECTS);
        CASE(VK_ERROR_FORMAT_NOT_SUPPORTED);
        CASE(VK_ERROR_FRAGMENTED_POOL);
        CASE(VK_ERROR_OUT_OF_POOL_MEMORY);
#undef CASE
    default:
        return "VK_ERROR_(unknown)";
    }
}

static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                    VkDebugUtilsMessageTypeFlagsEXT types,
                                                    const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)types;
    struct sb_vk *vk = user;
    if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)) {
        vk->validation_messages++;
        sb_error("validation: %s", data->pMessage);
    }
    return VK_FALSE;
}

static bool has_layer(const char *name)
{
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, NULL);
    VkLayerProperties *layers = calloc(n ? n : 1, sizeof(*layers));
    bool found = false;
    if (layers && vkEnumerateInstanceLayerProperties(&n, layers) == VK_SUCCESS)
        for (uint32_t i = 0; i < n; i++)
            found |= strcmp(layers[i].layerName, name) == 0;
    free(layers);
    return found;
}

static bool has_instance_extension(const char *name)
{
    uint32_t n = 0;
    vkEnumerateInstanceExtensionProperties(NULL, &n, NULL);
    VkExtensionProperties *ext = calloc(n ? n : 1, sizeof(*ext));
    bool found = false;
    if (ext && vkEnumerateInstanceExtensionProperties(NULL, &n, ext) == VK_SUCCESS)
        for (uint32_t i = 0; i < n; i++)
            found |= strcmp(ext[i].extensionName, name) == 0;
    free(ext);
    return found;
}

static bool contains_ci(const char *haystack, const char *needle)
{
    size_t n = strlen(needle);
    for (; *haystack; haystack++) {
        size_t i = 0;
        while (i < n && haystack[i] && tolower((unsigned char)haystack[i]) == tolower((unsigned char)needle[i]))
            i++;
        if (i == n)
            return true;
    }
    return n == 0;
}

static enum sb_result pick_device(struct sb_vk *vk, const char *want)
{
    uint32_t n = 0;
    VkResult r = vkEnumeratePhysicalDevices(vk->instance, &n, NULL);
    if (r != VK_SUCCESS || n == 0) {
        sb_error("no Vulkan device found (install mesa-vulkan-drivers for the CPU device, lavapipe)");
        return SB_ERR_NO_DEVICE;
    }
    VkPhysicalDevice *devs = calloc(n, sizeof(*devs));
    if (!devs)
        return SB_ERR_NOMEM;
    vkEnumeratePhysicalDevices(vk->instance, &n, devs);
    int chosen = -1;
    bool is_index = want && *want && strspn(want, "0123456789") == strlen(want);
    for (uint32_t i = 0; i < n && chosen < 0; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devs[i], &p);
        if (!want)
            chosen = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU ? (int)i : -1;
        else if (is_index)
            chosen = (uint32_t)atoi(want) == i ? (int)i : -1;
        else
            chosen = contains_ci(p.deviceName, want) ? (int)i : -1;
    }
    if (!want && chosen < 0)
        chosen = 0;
    if (chosen < 0) {
        sb_error("no Vulkan device matches --device \"%s\"; devices:", want);
        for (uint32_t i = 0; i < n; i++) {
            VkPhysicalDeviceProperties p;
            vkGetPhysicalDeviceProperties(devs[i], &p);
            sb_error("  %u: %s", i, p.deviceName);
        }
        free(devs);
        return SB_ERR_NO_DEVICE;
    }
    vk->physical_device = devs[chosen];
    free(devs);
    return SB_OK;
}

static bool has_device_extension(VkPhysicalDevice device, const char *name)
{
    uint32_t n = 0;
    vkEnumerateDeviceExtensionProperties(device, NULL, &n, NULL);
    VkExtensionProperties *ext = calloc(n ? n : 1, sizeof(*ext));
    if (!ext)
        return false;
    vkEnumerateDeviceExtensionProperties(device, NULL, &n, ext);
    bool found = false;
    for (uint32_t i = 0; i < n && !found; i++)
        found = strcmp(ext[i].extensionName, name) == 0;
    free(ext);
    return found;
}

static bool env_flag(const char *name)
{
    const char *env = getenv(name);
    return env && *env && strcmp(env, "0") != 0;
}

struct sb_vk_params sb_vk_params_from_env(void)
{
    return (struct sb_vk_params){
        .validate = env_flag("SKYBAKE_VALIDATE"),
        .statistics = env_flag("SKYBAKE_PIPELINE_STATS"),
    };
}

enum sb_result sb_vk_create(const struct sb_vk_params *params, struct sb_vk **out)
{
    enum sb_result res = SB_OK;
    *out = NULL;
    double t_start = sb_now_s();
    struct sb_vk *vk = calloc(1, sizeof(*vk));
    if (!vk)
        return SB_ERR_NOMEM;

    if (params->validate && !has_layer(VALIDATION_LAYER)) {
        sb_error("validation requested but %s is not installed (Debian: vulkan-validationlayers)", VALIDATION_LAYER);
        res = SB_ERR_VULKAN;
        goto cleanup;
    }
    bool debug_utils = has_instance_extension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    const char *layers[] = {VALIDATION_LAYER};
    const char *extensions[17];
    uint32_t extension_count = 0;
    if (debug_utils)
        extensions[extension_count++] = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    for (uint32_t i = 0; i < params->instance_extension_count && extension_count < 17; i++) {
        if (!has_instance_extension(params->instance_extensions[i])) {
            sb_error("the window needs the Vulkan instance extension %s, which no driver offers",
                     params->instance_extensions[i]);
            res = SB_ERR_NO_DEVICE;
            goto cleanup;
        }
        extensions[extension_count++] = params->instance_extensions[i];
    }
    VkApplicationInfo app = {
        .sType = VK_STRUCTURE_TYPE_APPLICATION_INFO,
        .pApplicationName = "skybake",
        .pEngineName = "skybake",
        .apiVersion = params->graphics ? VK_API_VERSION_1_3 : VK_API_VERSION_1_2,
    };
    VkDebugUtilsMessengerCreateInfoEXT messenger_info = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity =
            VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT,
        .pfnUserCallback = on_validation,
        .pUserData = vk,
    };
    /* Validation includes synchronisation validation: a missing barrier
     * between two passes or dispatches is a message like any other (it
     * finds hazards on lavapipe too, whose queue runs in order). */
    static const VkValidationFeatureEnableEXT enabled_features[] = {
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT validation_features = {
        .sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT,
        .pNext = debug_utils ? &messenger_info : NULL,
        .enabledValidationFeatureCount = 1,
        .pEnabledValidationFeatures = enabled_features,
    };
    VkInstanceCreateInfo instance_info = {
        .sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
        .pNext = params->validate ? (const void *)&validation_features : NULL,
        .pApplicationInfo = &app,
        .enabledLayerCount = params->validate ? 1 : 0,
        .ppEnabledLayerNames = layers,
        .enabledExtensionCount = extension_count,
        .ppEnabledExtensionNames = extensions,
    };
    VkResult r = vkCreateInstance(&instance_info, NULL, &vk->instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER) {
        sb_error("no Vulkan device found: no driver accepts Vulkan 1.2 (install mesa-vulkan-drivers for lavapipe)");
        res = SB_ERR_NO_DEVICE;
        goto cleanup;
    }
    VK(r);
    double t_instance = sb_now_s();
    if (params->validate && debug_utils) {
        PFN_vkCreateDebugUtilsMessengerEXT create_messenger =
            (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(vk->instance, "vkCreateDebugUtilsMessengerEXT");
        if (create_messenger)
            VK(create_messenger(vk->instance, &messenger_info, NULL, &vk->messenger));
    }
    if (debug_utils)
        vk->set_object_name =
            (PFN_vkSetDebugUtilsObjectNameEXT)vkGetInstanceProcAddr(vk->instance, "vkSetDebugUtilsObjectNameEXT");

    if ((res = pick_device(vk, params->device)))
        goto cleanup;
    vkGetPhysicalDeviceProperties(vk->physical_device, &vk->properties);
    vkGetPhysicalDeviceMemoryProperties(vk->physical_device, &vk->memory_properties);
    uint32_t need = params->graphics ? VK_API_VERSION_1_3 : VK_API_VERSION_1_2;
    if (vk->properties.apiVersion < need) {
        sb_error("%s supports Vulkan %u.%u; %s needs %u.%u", vk->properties.deviceName,
                 VK_API_VERSION_MAJOR(vk->properties.apiVersion), VK_API_VERSION_MINOR(vk->properties.apiVersion),
                 params->graphics ? "rendering" : "baking", VK_API_VERSION_MAJOR(need), VK_API_VERSION_MINOR(need));
        res = SB_ERR_NO_DEVICE;
        goto cleanup;
    }
    VkPhysicalDeviceSubgroupProperties subgroup = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceDriverProperties driver = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES,
                                               .pNext = &subgroup};
    VkPhysicalDeviceProperties2 props2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &driver};
    vkGetPhysicalDeviceProperties2(vk->physical_device, &props2);
    vk->compute_subgroup_ops =
        subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT ? subgroup.supportedOperations : 0;
    snprintf(vk->driver_name, sizeof(vk->driver_name), "%s", driver.driverName);
    snprintf(vk->driver_info, sizeof(vk->driver_info), "%s", driver.driverInfo);

    uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(vk->physical_device, &nq, NULL);
    VkQueueFamilyProperties qf[16];
    if (nq > 16)
        nq = 16;
    vkGetPhysicalDeviceQueueFamilyProperties(vk->physical_device, &nq, qf);
    int family = -1;
    for (uint32_t i = 0; i < nq && family < 0; i++) /* prefer a queue that does both */
        if ((qf[i].queueFlags & (VK_QUEUE_COMPUTE_BIT | VK_QUEUE_GRAPHICS_BIT)) ==
                (VK_QUEUE_COMPUTE_BIT | VK_QUEUE_GRAPHICS_BIT) &&
            (!params->can_present || params->can_present(vk->instance, vk->physical_device, i)))
            family = (int)i;
    if (params->can_present && family < 0) {
        sb_error("%s has no queue that renders and presents to the window", vk->properties.deviceName);
        res = SB_ERR_NO_DEVICE;
        goto cleanup;
    }
    if (params->can_present && !has_device_extension(vk->physical_device, VK_KHR_SWAPCHAIN_EXTENSION_NAME)) {
        sb_error("%s cannot present to a window (no %s)", vk->properties.deviceName, VK_KHR_SWAPCHAIN_EXTENSION_NAME);
        res = SB_ERR_NO_DEVICE;
        goto cleanup;
    }
    vk->present = params->can_present != NULL;
    for (uint32_t i = 0; i < nq && family < 0 && !params->graphics; i++)
        if (qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT)
            family = (int)i;
    if (family < 0) {
        sb_error("%s has no %s queue", vk->properties.deviceName,
                 params->graphics ? "graphics and compute" : "compute");
        res = SB_ERR_NO_DEVICE;
        goto cleanup;
    }
    vk->queue_family = (uint32_t)family;
    vk->has_timestamps = qf[family].timestampValidBits > 0 && vk->properties.limits.timestampPeriod > 0;
    vk->timestamp_period_ns = vk->properties.limits.timestampPeriod;

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
        .queueFamilyIndex = vk->queue_family,
        .queueCount = 1,
        .pQueuePriorities = &priority,
    };
    VkPhysicalDeviceVulkan13Features features13 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
        .dynamicRendering = VK_TRUE,
    };
    VkPhysicalDeviceVulkan12Features features12 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES,
        .pNext = params->graphics ? &features13 : NULL,
        .hostQueryReset = VK_TRUE,
    };
    VkPhysicalDeviceFeatures features = {0};
    if (params->graphics) {
        VkPhysicalDeviceVulkan13Features have13 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
        VkPhysicalDeviceFeatures2 have = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &have13};
        vkGetPhysicalDeviceFeatures2(vk->physical_device, &have);
        if (!have13.dynamicRendering) {
            sb_error("%s does not offer dynamic rendering, which rendering needs", vk->properties.deviceName);
            res = SB_ERR_NO_DEVICE;
            goto cleanup;
        }
        features.depthClamp = have.features.depthClamp;
        vk->depth_clamp = have.features.depthClamp;
        vk->graphics = true;
    }
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executable_features = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR,
        .pNext = &features12,
        .pipelineExecutableInfo = VK_TRUE,
    };
    const char *device_extensions[2];
    uint32_t device_extension_count = 0;
    vk->statistics = params->statistics &&
                     has_device_extension(vk->physical_device, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
    if (vk->statistics)
        device_extensions[device_extension_count++] = VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME;
    if (vk->present)
        device_extensions[device_extension_count++] = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
    if (params->statistics && !vk->statistics)
        sb_warn("%s does not report pipeline statistics (no %s)", vk->properties.deviceName,
                VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
    VkDeviceCreateInfo device_info = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
        .pNext = vk->statistics ? (void *)&executable_features : (void *)&features12,
        .enabledExtensionCount = device_extension_count,
        .ppEnabledExtensionNames = device_extensions,
        .pEnabledFeatures = &features,
        .queueCreateInfoCount = 1,
        .pQueueCreateInfos = &queue_info,
    };
    double t_chosen = sb_now_s();
    VK(vkCreateDevice(vk->physical_device, &device_info, NULL, &vk->device));
    vkGetDeviceQueue(vk->device, vk->queue_family, 0, &vk->queue);
    VkCommandPoolCreateInfo pool_info = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
        .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
        .queueFamilyIndex = vk->queue_family,
    };
    VK(vkCreateCommandPool(vk->device, &pool_info, NULL, &vk->command_pool));
    sb_debug("device: %s (%s %s); the instance in %.1f ms, the device chosen in %.1f and made in %.1f",
             vk->properties.deviceName, vk->driver_name, vk->driver_info, 1e3 * (t_instance - t_start),
             1e3 * (t_chosen - t_instance), 1e3 * (sb_now_s() - t_chosen));
    *out = vk;
    return SB_OK;

cleanup:
    sb_vk_destroy(&vk);
    return res;
}

void sb_vk_destroy(struct sb_vk **pvk)
{
    struct sb_vk *vk = *pvk;
    if (!vk)
        return;
    double t_start = sb_now_s();
    if (vk->device) {
        vkDeviceWaitIdle(vk->device);
        sb_vk_pipelines_finish(vk);
        if (vk->command_pool)
            vkDestroyCommandPool(vk->device, vk->command_pool, NULL);
        vkDestroyDevice(vk->device, NULL);
    }
    if (vk->messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger =
            (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(vk->instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy_messenger)
            destroy_messenger(vk->instance, vk->messenger, NULL);
    }
    if (vk->instance)
        vkDestroyInstance(vk->instance, NULL);
    if (vk->device)
        sb_debug("device: released in %.1f ms", 1e3 * (sb_now_s() - t_start));
    free(vk);
    *pvk = NULL;
}

static int memory_type(const struct sb_vk *vk, uint32_t type_bits, VkMemoryPropertyFlags want)
{
    for (uint32_t i = 0; i < vk->memory_properties.memoryTypeCount; i++)
        if ((type_bits & (1u << i)) && (vk->memory_properties.memoryTypes[i].propertyFlags & want) == want)
            return (int)i;
    return -1;
}

enum sb_result sb_vk_allocate(struct sb_vk *vk, const VkMemoryRequirements *req, VkMemoryPropertyFlags required,
                              VkMemoryPropertyFlags preferred, const char *name, VkDeviceMemory *memory,
                              VkMemoryPropertyFlags *flags)
{
    enum sb_result res = SB_OK;
    *memory = VK_NULL_HANDLE;
    int type = memory_type(vk, req->memoryTypeBits, required | preferred);
    if (type < 0)
        type = memory_type(vk, req->memoryTypeBits, required);
    if (type < 0) {
        sb_error("%s: no memory type with the properties 0x%x", name, (unsigned)required);
        return SB_ERR_VULKAN;
    }
    VkMemoryAllocateInfo alloc = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
        .allocationSize = req->size,
        .memoryTypeIndex = (uint32_t)type,
    };
    VK(vkAllocateMemory(vk->device, &alloc, NULL, memory));
    if (flags)
        *flags = vk->memory_properties.memoryTypes[type].propertyFlags;
cleanup:
    return res;
}

enum sb_result sb_vk_begin_once(struct sb_vk *vk, VkCommandBuffer *cmd)
{
    enum sb_result res = SB_OK;
    *cmd = VK_NULL_HANDLE;
    VkCommandBufferAllocateInfo alloc = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = vk->command_pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    VK(vkAllocateCommandBuffers(vk->device, &alloc, cmd));
    VkCommandBufferBeginInfo begin = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    VK(vkBeginCommandBuffer(*cmd, &begin));
    return SB_OK;

cleanup:
    if (*cmd)
        vkFreeCommandBuffers(vk->device, vk->command_pool, 1, cmd);
    *cmd = VK_NULL_HANDLE;
    return res;
}

enum sb_result sb_vk_end_once(struct sb_vk *vk, VkCommandBuffer cmd)
{
    enum sb_result res = SB_OK;
    VkFence fence = VK_NULL_HANDLE;
    VK(vkEndCommandBuffer(cmd));
    VkFenceCreateInfo finfo = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK(vkCreateFence(vk->device, &finfo, NULL, &fence));
    VkSubmitInfo submit = {
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
        .commandBufferCount = 1,
        .pCommandBuffers = &cmd,
    };
    VK(vkQueueSubmit(vk->queue, 1, &submit, fence));
    VK(vkWaitForFences(vk->device, 1, &fence, VK_TRUE, UINT64_MAX));

cleanup:
    if (fence)
        vkDestroyFence(vk->device, fence, NULL);
    vkFreeCommandBuffers(vk->device, vk->command_pool, 1, &cmd);
    return res;
}

unsigned sb_vk_validation_messages(const struct sb_vk *vk)
{
    return vk->validation_messages;
}

void sb_vk_device_info(const struct sb_vk *vk, struct sb_device_info *info)
{
    memset(info, 0, sizeof(*info));
    snprintf(info->name, sizeof(info->name), "%s", vk->properties.deviceName);
    snprintf(info->driver, sizeof(info->driver), "%s %s", vk->driver_name, vk->driver_info);
    uint32_t v = vk->properties.apiVersion;
    snprintf(info->api_version, sizeof(info->api_version), "%u.%u.%u", VK_API_VERSION_MAJOR(v), VK_API_VERSION_MINOR(v),
             VK_API_VERSION_PATCH(v));
    info->vendor_id = vk->properties.vendorID;
    info->device_id = vk->properties.deviceID;
}

void sb_vk_name(struct sb_vk *vk, VkObjectType type, uint64_t handle, const char *name)
{
    if (!vk->set_object_name || !name)
        return;
    VkDebugUtilsObjectNameInfoEXT info = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT,
        .objectType = type,
        .objectHandle = handle,
        .pObjectName = name,
    };
    vk->set_object_name(vk->device, &info);
}
