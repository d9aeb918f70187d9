/*
 * A BVH (geometry/bvh.h) on the device, and ray casts against it in a
 * compute kernel (shaders/raycast.comp, the traversal of bvh.glsl): the
 * path the probe bakes take, which the tests and the bench check against
 * Embree. The same compute path runs on every device (lavapipe has no
 * ray-tracing extensions), so results compare across devices.
 */
#ifndef SB_BAKER_RAYCAST_H
#define SB_BAKER_RAYCAST_H

#include <stdbool.h>
#include <stdint.h>

#include "bvh.h"
#include "compute.h"

struct sb_raycaster {
    struct sb_vk *vk;
    struct sb_buffer nodes, triangles; /* the BVH, as bvh.glsl reads it */
    bool instanced;                    /* two levels: the kernels built with BVH_INSTANCES */
    struct sb_pipeline pipeline;
    struct sb_buffer rays, hits; /* sized for the last cast */
    uint32_t capacity;
};

/* A kernel's code hash for bake keys: both its builds (one level, and
 * BVH_INSTANCES), so that a change to either rebakes. */
void sb_kernel_code_hash(const void *one_level, size_t one_size, const void *instanced, size_t instanced_size,
                         char out[33]);

/* Upload `bvh` (which may be freed afterwards); its kernels are the
 * two-level builds when it has instances. */
enum sb_result sb_raycaster_create(struct sb_vk *vk, const struct sb_bvh *bvh, struct sb_raycaster **raycaster);
/* The kernel sb_raycaster_create makes, for a BVH of instances or not. */
struct sb_pipeline_params sb_raycast_kernel(bool instanced);

/* Free; accepts a pointer to NULL and sets it to NULL. */
void sb_raycaster_destroy(struct sb_raycaster **raycaster);

/*
 * Cast `count` rays: rays[8 i ..] = origin (m), tmin, direction (any
 * length; t is in its units), tmax. hits[4 i ..] = t, the triangle's bits
 * (SB_BVH_MISS, or the mesh's triangle index | SB_BVH_BACK_FACE on a back
 * face, as a uint32_t), the instance's index (SB_BVH_NO_INSTANCE in a
 * one-level BVH, as a uint32_t), 0. `any`: stop at the first hit found. *gpu_ms
 * (may be NULL) gets the kernels' GPU time.
 */
enum sb_result sb_raycaster_cast(struct sb_raycaster *raycaster, const float *rays, uint32_t count, bool any,
                                 float *hits, double *gpu_ms);

/* A probe kernel's buffers: probes, one vec4 a probe (its position, then
 * valid[i], or 1 when valid is NULL), and results, `floats` a probe. */
enum sb_result sb_probe_buffers_create(struct sb_vk *vk, const float *positions, const float *valid,
                                       uint32_t probe_count, uint32_t floats, struct sb_buffer *probes,
                                       struct sb_buffer *results);

/* A probe kernel's passes as work done of total (sb_progress: probes
 * times passes), and how many probes a dispatch takes: about half a
 * second's worth, so that a slow device (lavapipe's cast of a level's
 * probes takes minutes) shows its progress and a fast one takes a pass in
 * one or two dispatches. */
struct sb_probe_work {
    const char *what;
    uint64_t done, total;
    uint32_t rows; /* rows of SB_PROBE_ROW workgroups a dispatch (0: 8 to begin) */
};
#define SB_PROBE_ROW 1024

/* Begin work of `passes` passes over `probe_count` probes. */
void sb_probe_work_begin(struct sb_probe_work *work, const char *what, uint32_t passes, uint32_t probe_count);

/* Run one pass of a probe kernel (bound, its push constants `push`): one
 * workgroup a probe, probe gl_WorkGroupID.x + gl_WorkGroupID.y
 * gl_NumWorkGroups.x; with `work`, in rows of SB_PROBE_ROW dispatched a
 * few at a time as it says, its progress shown (NULL: one dispatch, rows
 * of up to 65535). Its GPU time is added to *gpu_ms (may be NULL). */
enum sb_result sb_probe_kernel_pass(struct sb_vk *vk, struct sb_pipeline *pipeline, const void *push,
                                    uint32_t probe_count, struct sb_probe_work *work, double *gpu_ms);

/* One pass, then read `results` into out. *gpu_ms (may be NULL) gets the
 * GPU time. */
enum sb_result sb_probe_kernel_run(struct sb_vk *vk, struct sb_pipeline *pipeline, const void *push,
                                   uint32_t probe_count, struct sb_buffer *results, void *out, double *gpu_ms);

#endif
