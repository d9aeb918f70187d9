/*
 * Embree (robust mode), the independent CPU reference for ray casts in the
 * tests and the bench: a scene of one mesh, and closest-hit casts in the
 * raycast kernel's ray and hit layouts (raycast.h) on every core.
 */
#ifndef SB_BAKER_EMBREE_REF_H
#define SB_BAKER_EMBREE_REF_H

#include <embree3/rtcore.h>
#include <stdbool.h>

#include "bvh.h"
#include "mesh.h"

struct sb_embree {
    RTCDevice device;
    RTCScene scene;
    uint32_t *triangle_base; /* an instanced scene's: each instance's mesh's first triangle */
};

/* A scene of the mesh's triangles (robust mode); false if Embree refuses. */
bool sb_embree_create(const struct sb_mesh *mesh, struct sb_embree *e);
/* A scene of instances of the meshes (Embree's own two levels, each mesh's
 * scene at RTC_BUILD_QUALITY_MEDIUM; instance i is Embree's instance i);
 * hits number the triangles as sb_bvh_build_instanced does. */
bool sb_embree_create_instanced(const struct sb_mesh *const *meshes, uint32_t mesh_count,
                                const struct sb_bvh_instance *instances, uint32_t instance_count, struct sb_embree *e);
void sb_embree_destroy(struct sb_embree *e);

/* The wall time of Embree's build of the mesh's scene (robust mode) at
 * `quality` on every core, in ms (the bench's yardstick); < 0 if Embree
 * refuses. */
double sb_embree_build_ms(const struct sb_mesh *mesh, enum RTCBuildQuality quality);

/* Closest hits of `count` rays (8 floats each: origin, tmin, direction,
 * tmax) into hits (4 floats each: t, triangle bits or SB_BVH_MISS, the
 * instance's bits or SB_BVH_NO_INSTANCE, 0: the raycast kernel's),
 * on every core; returns the wall time in seconds. */
double sb_embree_cast(const struct sb_embree *e, const float *rays, uint32_t count, float *hits);

#endif
