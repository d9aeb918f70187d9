/*
 * Layouts and pipelines, the context's: compute, and graphics with dynamic
 * rendering (no render pass objects), dynamic viewport and scissor, and no
 * vertex input (shaders pull vertices from storage buffers by index).
 *
 * Each is made once for what defines it (Granite's request_pipeline_layout
 * and request_program): a layout for its bindings and push constants, a
 * pipeline for its SPIR-V, specialization, layout and fixed state. The
 * context owns them until sb_vk_destroy, so a renderer or a bake made again
 * on the same context compiles nothing it compiled before (a driver's
 * compile is most of the cost of creating a renderer: on lavapipe 80 ms a
 * pipeline on average over the runtime test). Never destroy what these
 * functions return. For the context's thread, like the context.
 */
#ifndef SB_VK_PIPELINE_H
#define SB_VK_PIPELINE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "context.h"

/* A descriptor set layout of `bindings` (none with immutable samplers) and
 * a pipeline layout of that one set and `push_size` bytes of push
 * constants (0: none) for `push_stages`. */
enum sb_result sb_vk_layout(struct sb_vk *vk, const VkDescriptorSetLayoutBinding *bindings, uint32_t binding_count,
                            VkShaderStageFlags push_stages, uint32_t push_size, VkDescriptorSetLayout *set_layout,
                            VkPipelineLayout *layout);

/* A compute pipeline from SPIR-V (entry point "main") on a layout from
 * sb_vk_layout, its specialization constants set by `specialization`
 * (NULL: the shader's defaults); `name` is its debug name (the first
 * caller's) and, with sb_vk_params.statistics, names the driver's
 * statistics logged for its first caller (graphics pipelines capture none). */
enum sb_result sb_compute_pipeline_create(struct sb_vk *vk, VkPipelineLayout layout, const uint32_t *spirv,
                                          size_t spirv_size, const VkSpecializationInfo *specialization,
                                          const char *name, VkPipeline *pipeline);

/* A compute kernel to compile ahead: what sb_compute_pipeline_create takes. */
struct sb_compute_kernel {
    VkPipelineLayout layout; /* from sb_vk_layout */
    const uint32_t *spirv;
    size_t spirv_size; /* bytes */
    const VkSpecializationInfo *specialization;
};

/*
 * Compile the kernels the context does not hold yet on up to `threads`
 * threads at once, for sb_compute_pipeline_create to find: a driver's first
 * compile of a large kernel takes up to a second, and a bake creates its
 * kernels one after another. A kernel listed twice compiles once; one that
 * fails here is compiled again, and its failure reported, by
 * sb_compute_pipeline_create.
 */
void sb_compute_pipelines_prepare(struct sb_vk *vk, const struct sb_compute_kernel *kernels, uint32_t count,
                                  int threads);
/* How many of them nothing has asked for yet. */
uint32_t sb_compute_pipelines_unused(const struct sb_vk *vk);

struct sb_graphics_pipeline_params {
    VkPipelineLayout layout; /* from sb_vk_layout */
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

/* How many pipelines the context holds: each one compiled once. */
uint32_t sb_vk_pipeline_count(const struct sb_vk *vk);

/* Destroy every layout and pipeline the context holds (sb_vk_destroy). */
void sb_vk_pipelines_finish(struct sb_vk *vk);

#endif
