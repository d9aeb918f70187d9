#include "pipeline.h"

#include <stdio.h>

#include "log.h"

static enum sb_result shader_module(struct sb_vk *vk, const uint32_t *spirv, size_t size, VkShaderModule *module)
{
    enum sb_result res = SB_OK;
    VkShaderModuleCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
        .codeSize = size,
        .pCode = spirv,
    };
    VK(vkCreateShaderModule(vk->device, &info, NULL, module));
cleanup:
    return res;
}

/* Log what the driver says of the pipeline's code, one line per executable:
 * "NAME (EXECUTABLE): Register Count 64, ..." as it names them. */
static void log_statistics(struct sb_vk *vk, VkPipeline pipeline, const char *name)
{
    PFN_vkGetPipelineExecutablePropertiesKHR get_properties =
        (PFN_vkGetPipelineExecutablePropertiesKHR)vkGetDeviceProcAddr(vk->device,
                                                                      "vkGetPipelineExecutablePropertiesKHR");
    PFN_vkGetPipelineExecutableStatisticsKHR get_statistics =
        (PFN_vkGetPipelineExecutableStatisticsKHR)vkGetDeviceProcAddr(vk->device,
                                                                      "vkGetPipelineExecutableStatisticsKHR");
    if (!get_properties || !get_statistics)
        return;
    VkPipelineInfoKHR info = {.sType = VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR, .pipeline = pipeline};
    VkPipelineExecutablePropertiesKHR executables[4];
    uint32_t n = 4;
    for (uint32_t i = 0; i < n; i++)
        executables[i] =
            (VkPipelineExecutablePropertiesKHR){.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR};
    if (get_properties(vk->device, &info, &n, executables) < 0)
        return;
    for (uint32_t e = 0; e < n; e++) {
        VkPipelineExecutableInfoKHR which = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR,
            .pipeline = pipeline,
            .executableIndex = e,
        };
        VkPipelineExecutableStatisticKHR stats[32];
        uint32_t count = 32;
        for (uint32_t i = 0; i < count; i++)
            stats[i] = (VkPipelineExecutableStatisticKHR){.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR};
        if (get_statistics(vk->device, &which, &count, stats) < 0)
            continue;
        char line[1024];
        int len = snprintf(line, sizeof(line), "%s (%s):", name, executables[e].name);
        for (uint32_t i = 0; i < count && len > 0 && (size_t)len < sizeof(line); i++) {
            const VkPipelineExecutableStatisticKHR *st = &stats[i];
            const char *sep = i ? "," : "";
            size_t room = sizeof(line) - (size_t)len;
            if (st->format == VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR)
                len += snprintf(line + len, room, "%s %s %s", sep, st->name, st->value.b32 ? "yes" : "no");
            else if (st->format == VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR)
                len += snprintf(line + len, room, "%s %s %lld", sep, st->name, (long long)st->value.i64);
            else if (st->format == VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR)
                len += snprintf(line + len, room, "%s %s %llu", sep, st->name, (unsigned long long)st->value.u64);
            else
                len += snprintf(line + len, room, "%s %s %g", sep, st->name, st->value.f64);
        }
        sb_info("%s", line);
    }
}

enum sb_result sb_compute_pipeline_compile(struct sb_vk *vk, VkPipelineLayout layout, const uint32_t *spirv,
                                           size_t spirv_size, const VkSpecializationInfo *specialization,
                                           VkPipeline *pipeline)
{
    VkShaderModule module = VK_NULL_HANDLE;
    *pipeline = VK_NULL_HANDLE;
    enum sb_result res = shader_module(vk, spirv, spirv_size, &module);
    if (res)
        return res;
    VkComputePipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage =
            {
                .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                .module = module,
                .pName = "main",
                .pSpecializationInfo = specialization,
            },
        .layout = layout,
        .flags =
            VK_PIPELINE_CREATE_DISPATCH_BASE_BIT | (vk->statistics ? VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR : 0),
    };
    VK(vkCreateComputePipelines(vk->device, VK_NULL_HANDLE, 1, &info, NULL, pipeline));
cleanup:
    vkDestroyShaderModule(vk->device, module, NULL);
    return res;
}

void sb_compute_pipeline_named(struct sb_vk *vk, VkPipeline pipeline, const char *name)
{
    sb_vk_name(vk, VK_OBJECT_TYPE_PIPELINE, (uint64_t)pipeline, name);
    if (vk->statistics)
        log_statistics(vk, pipeline, name);
}

enum sb_result sb_compute_pipeline_create(struct sb_vk *vk, VkPipelineLayout layout, const uint32_t *spirv,
                                          size_t spirv_size, const VkSpecializationInfo *specialization,
                                          const char *name, VkPipeline *pipeline)
{
    double t0 = sb_now_s();
    enum sb_result res = sb_compute_pipeline_compile(vk, layout, spirv, spirv_size, specialization, pipeline);
    if (res)
        return res;
    sb_debug("pipeline %s: compiled in %.1f ms", name, 1e3 * (sb_now_s() - t0));
    sb_compute_pipeline_named(vk, *pipeline, name);
    return SB_OK;
}

enum sb_result sb_graphics_pipeline_create(struct sb_vk *vk, const struct sb_graphics_pipeline_params *p,
                                           VkPipeline *pipeline)
{
    VkShaderModule modules[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
    *pipeline = VK_NULL_HANDLE;
    enum sb_result res = shader_module(vk, p->vertex_spirv, p->vertex_size, &modules[0]);
    if (!res && p->fragment_spirv)
        res = shader_module(vk, p->fragment_spirv, p->fragment_size, &modules[1]);
    if (res)
        goto cleanup;
    VkPipelineShaderStageCreateInfo stages[2] = {
        {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = VK_SHADER_STAGE_VERTEX_BIT,
            .module = modules[0],
            .pName = "main",
        },
        {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = VK_SHADER_STAGE_FRAGMENT_BIT,
            .module = modules[1],
            .pName = "main",
            .pSpecializationInfo = p->fragment_specialization,
        },
    };
    VkPipelineVertexInputStateCreateInfo vertex_input = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
    };
    VkPipelineInputAssemblyStateCreateInfo assembly = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
        .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST,
    };
    VkPipelineViewportStateCreateInfo viewport = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
        .viewportCount = 1,
        .scissorCount = 1,
    };
    bool bias = p->depth_bias_constant != 0.0f || p->depth_bias_slope != 0.0f;
    VkPipelineRasterizationStateCreateInfo raster = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
        .depthClampEnable = p->depth_clamp && vk->depth_clamp,
        .polygonMode = VK_POLYGON_MODE_FILL,
        .cullMode = p->cull_mode,
        .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE,
        .depthBiasEnable = bias,
        .depthBiasConstantFactor = p->depth_bias_constant,
        .depthBiasSlopeFactor = p->depth_bias_slope,
        .lineWidth = 1.0f,
    };
    VkPipelineMultisampleStateCreateInfo multisample = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
        .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT,
    };
    VkPipelineDepthStencilStateCreateInfo depth = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
        .depthTestEnable = VK_TRUE,
        .depthWriteEnable = VK_TRUE,
        .depthCompareOp = p->depth_compare,
    };
    const VkColorComponentFlags rgba =
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    const VkPipelineColorBlendAttachmentState blend_attachments[2] = {{.colorWriteMask = rgba},
                                                                      {.colorWriteMask = rgba}};
    const VkFormat color_formats[2] = {p->color_format, p->color_format2};
    uint32_t colors = p->color_format == VK_FORMAT_UNDEFINED ? 0 : p->color_format2 == VK_FORMAT_UNDEFINED ? 1 : 2;
    VkPipelineColorBlendStateCreateInfo blend = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
        .attachmentCount = colors,
        .pAttachments = blend_attachments,
    };
    const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
        .dynamicStateCount = 2,
        .pDynamicStates = dynamic_states,
    };
    VkPipelineRenderingCreateInfo rendering = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
        .colorAttachmentCount = colors,
        .pColorAttachmentFormats = color_formats,
        .depthAttachmentFormat = p->depth_format,
    };
    VkGraphicsPipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
        .pNext = &rendering,
        .stageCount = p->fragment_spirv ? 2 : 1,
        .pStages = stages,
        .pVertexInputState = &vertex_input,
        .pInputAssemblyState = &assembly,
        .pViewportState = &viewport,
        .pRasterizationState = &raster,
        .pMultisampleState = &multisample,
        .pDepthStencilState = &depth,
        .pColorBlendState = &blend,
        .pDynamicState = &dynamic,
        .layout = p->layout,
    };
    VK(vkCreateGraphicsPipelines(vk->device, VK_NULL_HANDLE, 1, &info, NULL, pipeline));
    sb_vk_name(vk, VK_OBJECT_TYPE_PIPELINE, (uint64_t)*pipeline, p->name);
cleanup:
    for (int i = 0; i < 2; i++)
        if (modules[i])
            vkDestroyShaderModule(vk->device, modules[i], NULL);
    return res;
}
