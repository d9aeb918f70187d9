/*
 * Storage buffers and compute pipelines on an sb_vk context, and timed,
 * synchronous dispatches. Buffers live in memory the host can map (device
 * local where the device offers such a type), which is right for the small
 * LUTs skybake bakes; large results are read back with sb_buffer_read. All
 * functions are for one thread at a time.
 */
#ifndef SB_VK_COMPUTE_H
#define SB_VK_COMPUTE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "context.h"

struct sb_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    VkDeviceSize size;
    void *mapped;        /* persistently mapped, coherent */
    bool host_cached;    /* the host reads `mapped` at memory speed */
    VkBufferView texels; /* its vec4 texels (sb_buffer_create_texels), or none */
};

/* A zero-filled storage buffer of `size` bytes (> 0). */
enum sb_result sb_buffer_create(struct sb_vk *vk, VkDeviceSize size, const char *name, struct sb_buffer *buffer);
/*
 * The same, that kernels may also read as texels: RGBA32F, each 16 bytes
 * of it, at a binding of sb_pipeline_params's texel_bindings
 * (`uniform samplerBuffer`, texelFetch). Such a read fetches a whole vec4
 * at once: where a kernel gathers at addresses that differ per invocation,
 * llvmpipe loads a storage buffer one component of one invocation at a
 * time, behind a bounds check each, and fetches a texel as one vector
 * load an invocation. SB_ERR_DEVICE_LIMIT where the device cannot hold
 * size / 16 texels in one view.
 */
enum sb_result sb_buffer_create_texels(struct sb_vk *vk, VkDeviceSize size, const char *name, struct sb_buffer *buffer);
/* Free a buffer; accepts a zeroed one. */
void sb_buffer_destroy(struct sb_vk *vk, struct sb_buffer *buffer);

/*
 * Copy the whole buffer into `out` (buffer->size bytes), after the work
 * submitted so far. Device-local memory that the host can map is uncached:
 * reading it directly crawls over the bus (1.5 s for 32 MB on an H200), so
 * unless the buffer's memory is cached on the host, the device copies it
 * into a cached staging buffer first.
 */
enum sb_result sb_buffer_read(struct sb_vk *vk, const struct sb_buffer *buffer, void *out);
/* Several buffers at once, buffers[i] into outs[i]: one staging copy, one
 * submission and one wait for them all (a large product's last step). */
enum sb_result sb_buffers_read(struct sb_vk *vk, int count, const struct sb_buffer *const *buffers, void *const *outs);

/* A kernel and its own descriptor set: the layouts and the pipeline are the
 * context's (pipeline.h), the set and its pool the sb_pipeline's. */
struct sb_pipeline {
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
    VkDescriptorPool descriptor_pool;
    VkDescriptorSet set;
    uint32_t binding_count;
    uint32_t texel_bindings;
    uint32_t push_size;
};

struct sb_pipeline_params {
    const uint32_t *spirv;   /* SPIR-V words, entry point "main" */
    size_t spirv_size;       /* in bytes */
    uint32_t binding_count;  /* storage buffers at bindings 0..count-1 of set 0 (at most 16) */
    uint32_t texel_bindings; /* those of them that are texel buffers instead (bit i: binding i) */
    uint32_t push_size;      /* bytes of push constants, 0 for none */
    const char *name;        /* debug name */
};

enum sb_result sb_pipeline_create(struct sb_vk *vk, const struct sb_pipeline_params *params,
                                  struct sb_pipeline *pipeline);
/* Free the pipeline's set; accepts a zeroed one. */
void sb_pipeline_destroy(struct sb_vk *vk, struct sb_pipeline *pipeline);

/*
 * Compile kernels ahead, on up to `threads` threads at once
 * (sb_compute_pipelines_prepare): sb_pipeline_create then finds them
 * compiled.
 */
void sb_pipelines_prepare(struct sb_vk *vk, const struct sb_pipeline_params *params, uint32_t count, int threads);

/* Point binding i at buffers[i] for every binding of the pipeline (a
 * texel binding at the buffer's texels, which it must have). */
void sb_pipeline_bind(struct sb_vk *vk, struct sb_pipeline *pipeline, const struct sb_buffer *const *buffers);

/*
 * Record, submit and wait for one dispatch of groups_x * groups_y * groups_z
 * workgroups. *gpu_ms receives the time between timestamps written before
 * and after it (0 when the queue has no timestamps). `push` may be NULL.
 */
enum sb_result sb_dispatch(struct sb_vk *vk, struct sb_pipeline *pipeline, const void *push, uint32_t groups_x,
                           uint32_t groups_y, uint32_t groups_z, double *gpu_ms);

/* The same, the workgroups' ids from base[] on (vkCmdDispatchBase: every
 * compute pipeline may take one). */
enum sb_result sb_dispatch_base(struct sb_vk *vk, struct sb_pipeline *pipeline, const void *push,
                                const uint32_t base[3], uint32_t groups_x, uint32_t groups_y, uint32_t groups_z,
                                double *gpu_ms);

/*
 * A GPU idles at its lowest clocks between short jobs (an H100 at 345 of
 * 1980 MHz) and raises them only after some tens of milliseconds of steady
 * work, so a bake or a frame of a few milliseconds timed cold measures the
 * clock governor, not the kernels (docs/accuracy.md, "GPU clocks").
 * sb_warm_up keeps the GPU busy for `warm_ms` of its own time
 * (shaders/warm_up.comp) and returns when that work is done; the benches
 * call it before each timed bake or frame: SB_WARM_UP_MS first, after
 * anything that may have left the GPU idle (a first bake compiles its
 * kernels), and SB_KEEP_WARM_MS before each of the rest, since the clocks
 * fall again within the gaps between short jobs. On a CPU device, or one
 * without timestamps, it does nothing.
 */
#define SB_WARM_UP_MS 200.0
#define SB_KEEP_WARM_MS 20.0
enum sb_result sb_warm_up(struct sb_vk *vk, double warm_ms);

#endif
