/*
 * A bounding volume hierarchy over a mesh's triangles, built on the CPU by
 * binned SAH (Wald 2007) and laid out for the GPU's traversal
 * (shaders/bvh.glsl) and the CPU's (sb_bvh_intersect), which share one
 * algorithm and one triangle test. Built on every thread (parallel.h) and
 * deterministic: the same triangles give the same bytes on any number of
 * threads. One level over one mesh, or two: a BVH a mesh and a top level
 * over placed instances of them (sb_bvh_build_instanced), in the same two
 * arrays, traced by the same loop.
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

/* An instance's record in the nodes (SB_BVH_INSTANCE_LEAF), two nodes. */
struct sb_bvh_instance_record {
    float to_object[3][4]; /* world to the mesh's space: rows of an affine 3 x 4 */
    uint32_t root;         /* the mesh's root node */
    uint32_t instance;     /* the instance's index */
    uint32_t flags;        /* SB_BVH_INSTANCE_WIDE (shaders/config.h), else 0 */
    uint32_t pad;
};

struct sb_bvh {
    uint32_t node_count, triangle_count, depth, max_leaf;
    uint32_t instance_count; /* 0: one level, over one mesh's triangles */
    struct sb_bvh_node *nodes;         /* owned; nodes[0] is the root */
    struct sb_bvh_triangle *triangles; /* owned; in leaf order */
};

/* A placed copy of a mesh (sb_bvh_build_instanced). */
struct sb_bvh_instance {
    uint32_t mesh;            /* its index in the meshes */
    double to_world[3][4];    /* object to world: rows of an affine 3 x 4, invertible */
};

/*
 * Build over every triangle of `mesh` (at least one). Leaves hold at most
 * SB_BVH_MAX_LEAF triangles, except where SB_BVH_MAX_DEPTH stops the
 * splitting (the traversal's stack is that deep). Returns SB_ERR_NOMEM or
 * SB_ERR_MESH (no triangle); *bvh is zeroed on failure.
 */
enum sb_result sb_bvh_build(const struct sb_mesh *mesh, struct sb_bvh *bvh);

/*
 * Build two levels: one BVH a mesh (as sb_bvh_build) and a top level over
 * the instances, one a leaf, laid out in one node array (the top level's
 * root at nodes[0], then the instances' records, then each mesh's nodes)
 * and one triangle array (each mesh's in turn; a triangle's index and its
 * material are offset by the triangles and materials of the meshes before
 * it, so that they index the meshes taken in order). Deterministic as
 * sb_bvh_build. Returns SB_ERR_NOMEM, SB_ERR_MESH (a mesh with no
 * triangle, an instance of no mesh, no instance, a transform that is not
 * finite and invertible) or SB_ERR_TOO_LARGE (past 2^31 triangles or
 * nodes); *bvh is zeroed on failure.
 */
enum sb_result sb_bvh_build_instanced(const struct sb_mesh *const *meshes, uint32_t mesh_count,
                                      const struct sb_bvh_instance *instances, uint32_t instance_count,
                                      struct sb_bvh *bvh);

/* Free and zero; accepts a zeroed BVH. */
void sb_bvh_finish(struct sb_bvh *bvh);

/* XXH3-128 of the nodes' and triangles' bytes. */
void sb_bvh_hash(const struct sb_bvh *bvh, char out[33]);

struct sb_hit {
    float t;           /* distance along the (unnormalised) direction */
    uint32_t triangle; /* the mesh's triangle index, SB_BVH_MISS when none */
    uint32_t instance; /* the instance's index, SB_BVH_NO_INSTANCE in a one-level BVH */
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
