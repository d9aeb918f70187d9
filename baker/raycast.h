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
    struct sb_pipeline pipeline;
    struct sb_buffer rays, hits; /* sized for the last cast */
    uint32_t capacity;
};

/* Upload `bvh` (which may be freed afterwards). */
enum sb_result sb_raycaster_create(struct sb_vk *vk, const struct sb_bvh *bvh, struct sb_raycaster **raycaster);
/* Free; accepts a pointer to NULL and sets it to NULL. */
void sb_raycaster_destroy(struct sb_raycaster **raycaster);

/*
 * Cast `count` rays: rays[8 i ..] = origin (m), tmin, direction (any
 * length; t is in its units), tmax. hits[4 i ..] = t, the triangle's bits
 * (SB_BVH_MISS, or the mesh's triangle index | SB_BVH_BACK_FACE on a back
 * face, as a uint32_t), u, v. `any`: stop at the first hit found. *gpu_ms
 * (may be NULL) gets the kernels' GPU time.
 */
enum sb_result sb_raycaster_cast(struct sb_raycaster *raycaster, const float *rays, uint32_t count, bool any,
                                 float *hits, double *gpu_ms);

#endif
