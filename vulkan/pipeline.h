/*
 * Pipelines on a layout the caller owns: compute, and graphics with dynamic
 * rendering (no render pass objects), dynamic viewport and scissor, and no
 * vertex input (shaders pull vertices from storage buffers by index).
 */
#ifndef SB_VK_PIPELINE_H
#define SB_VK_PIPELINE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "context.h"

/* A compute pipeline from SPIR-V (entry point "main"), its specialization
 * constants set by `specialization` (NULL: the shader's defaults); `name`
 * is its debug name. */
enum sb_result sb_compute_pipeline_create(struct sb_vk *vk, VkPipelineLayout layout, const uint32_t *spirv,
                                          size_t spirv_size, const VkSpecializationInfo *specialization,
                                          const char *name, VkPipeline *pipeline);
/* Its two halves: the compile alone (safe on any thread), then the name
 * and, with sb_vk_params.statistics, the driver's statistics logged. */
enum sb_result sb_compute_pipeline_compile(struct sb_vk *vk, VkPipelineLayout layout, const uint32_t *spirv,
                                           size_t spirv_size, const VkSpecializationInfo *specialization,
                                           VkPipeline *pipeline);
void sb_compute_pipeline_named(struct sb_vk *vk, VkPipeline pipeline, const char *name);

struct sb_graphics_pipeline_params {
    VkPipelineLayout layout;
    const uint32_t *vertex_spirv;
    size_t vertex_size;             /* bytes */
    const uint32_t *fragment_spirv; /* NULL: depth only */
    size_t fragment_size;
    VkFormat color_format;  /* VK_FORMAT_UNDEFINED (0): no colour attachment */
    VkFormat color_format2; /* a second colour attachment's (location 1), or 0 */
    VkFormat depth_format;  /* the depth attachment's format; it is always written */
    VkCompareOp depth_compare;
    VkCullModeFlags cull_mode; /* 0: none; front faces are counter-clockwise */
    bool depth_clamp;          /* clamp instead of clipping at near and far (needs vk->depth_clamp) */
    float depth_bias_constant; /* 0 and 0: no bias */
    float depth_bias_slope;
    const VkSpecializationInfo *fragment_specialization; /* NULL: the fragment shader's defaults */
    const char *name;
};

enum sb_result sb_graphics_pipeline_create(struct sb_vk *vk, const struct sb_graphics_pipeline_params *params,
                                           VkPipeline *pipeline);

#endif
