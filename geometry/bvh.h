/*
 * A bounding volume hierarchy over a mesh's triangles, built on the CPU by
 * binned SAH (Wald 2007) and laid out for the GPU's traversal
 * (shaders/bvh.glsl) and the CPU's (sb_bvh_intersect), which share one
 * algorithm and one triangle test. Built on every thread (parallel.h) and
 * deterministic: the same triangles give the same bytes on any number of
 * threads.
 */
#ifndef SB_GEOMETRY_BVH_H
#define SB_GEOMETRY_BVH_H

#include <stdbool.h>
#include <stdint.h>

#include "config.h"
#include "mesh.h"
#include "result.h"

/* The builder's recipe, in the bake keys of every product that traces the
 * BVH: bump it whenever the bytes built for some mesh change (the splits,
 * the order, the layout), since a hit between coincident triangles
 * follows them. 3: every partition stable, laid out as on one thread
 * (2: built on every thread, stable partitions above 8192 triangles, as
 * many bins as triangles below 32). */
#define SB_BVH_VERSION 3

/* One node, 32 bytes (two vec4s in GLSL). count 0: an interior node whose
 * children are nodes first and first + 1; else a leaf of `count` triangles
 * from triangles[first]. */
struct sb_bvh_node {
    float min[3];
    uint32_t first;
    float max[3];
    uint32_t count;
};

/* One triangle as the traversal reads it, 48 bytes (three vec4s): a vertex
 * and the two edges from it, the mesh's triangle index and its material. */
struct sb_bvh_triangle {
    float v0[3];
    uint32_t triangle;
    float e1[3];
    uint32_t material;
    float e2[3];
    uint32_t pad;
};

struct sb_bvh {
    uint32_t node_count, triangle_count, depth, max_leaf;
    struct sb_bvh_node *nodes;         /* owned; nodes[0] is the root */
    struct sb_bvh_triangle *triangles; /* owned; in leaf order */
};

/*
 * Build over every triangle of `mesh` (at least one). Leaves hold at most
 * SB_BVH_MAX_LEAF triangles, except where SB_BVH_MAX_DEPTH stops the
 * splitting (the traversal's stack is that deep). Returns SB_ERR_NOMEM or
 * SB_ERR_MESH (no triangle); *bvh is zeroed on failure.
 */
enum sb_result sb_bvh_build(const struct sb_mesh *mesh, struct sb_bvh *bvh);

/* Free and zero; accepts a zeroed BVH. */
void sb_bvh_finish(struct sb_bvh *bvh);

/* XXH3-128 of the nodes' and triangles' bytes. */
void sb_bvh_hash(const struct sb_bvh *bvh, char out[33]);

struct sb_hit {
    float t;           /* distance along the (unnormalised) direction */
    uint32_t triangle; /* the mesh's triangle index, SB_BVH_MISS when none */
    float u, v;        /* barycentrics of v1 and v2 */
    bool back_face;    /* the ray met the triangle's back (counter-clockwise front) */
};

/*
 * The closest hit with t in (tmin, tmax), or any hit when `any` is set,
 * by the same traversal and the same fp32 triangle test as the GPU's:
 * false and hit->triangle = SB_BVH_MISS when there is none.
 */
bool sb_bvh_intersect(const struct sb_bvh *bvh, const float origin[3], const float direction[3], float tmin, float tmax,
                      bool any, struct sb_hit *hit);

#endif
