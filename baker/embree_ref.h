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
};

/* A scene of the mesh's triangles (robust mode); false if Embree refuses. */
bool sb_embree_create(const struct sb_mesh *mesh, struct sb_embree *e);
void sb_embree_destroy(struct sb_embree *e);

/* The wall time of Embree's build of the mesh's scene (robust mode) at
 * `quality` on every core, in ms (the bench's yardstick); < 0 if Embree
 * refuses. */
double sb_embree_build_ms(const struct sb_mesh *mesh, enum RTCBuildQuality quality);

/* Closest hits of `count` rays (8 floats each: origin, tmin, direction,
 * tmax) into hits (4 floats each: t, triangle bits or SB_BVH_MISS, u, v),
 * on every core; returns the wall time in seconds. */
double sb_embree_cast(const struct sb_embree *e, const float *rays, uint32_t count, float *hits);

#endif
