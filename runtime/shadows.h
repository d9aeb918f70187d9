/*
 * Cascaded shadow maps for a camera and the sun: the practical split scheme
 * (a blend of logarithmic and uniform splits, Zhang et al. 2006), one
 * bounding sphere per cascade so a cascade's size does not change as the
 * camera turns, and its centre snapped to whole shadow texels in the sun's
 * frame so shadows do not swim as the camera moves.
 */
#ifndef SB_RUNTIME_SHADOWS_H
#define SB_RUNTIME_SHADOWS_H

#include <stdbool.h>
#include <stdint.h>

#include "transform.h"
#include "view_gpu.h"

struct sb_cascade_params {
    double near_m;          /* the camera's near plane */
    double distance_m;      /* where the last cascade ends */
    double lambda;          /* 0: uniform splits, 1: logarithmic */
    double fov_y, aspect;   /* the camera's (radians) */
    unsigned map_size;      /* texels per side */
    double caster_margin_m; /* how far toward the sun, beyond a cascade's sphere, casters are kept */
};

struct sb_cascades {
    double ends_m[SB_CASCADES];            /* view depth where each cascade ends */
    double radius_m[SB_CASCADES];          /* each cascade's bounding sphere */
    double texel_m[SB_CASCADES];           /* a shadow texel's width */
    struct sb_mat4 view_proj[SB_CASCADES]; /* camera-relative world (m) to the cascade's clip space */
};

/*
 * camera_m: the camera in the world; forward: its unit view direction;
 * sun: unit vector toward the sun. Matrices take offsets from the camera, but
 * the snapping happens in absolute world coordinates, so a moving camera
 * sees the same texel grid.
 */
void sb_cascades_compute(const struct sb_cascade_params *params, const double camera_m[3], const double forward[3],
                         const double sun[3], struct sb_cascades *out);

/*
 * Only the part of a cascade where casters project is cleared and drawn:
 * clearing 4 x 2048^2 depth texels took the H100 1.2 ms (it has 8 ROPs), a
 * frame of a few hundred triangles rarely covers a tenth of them, and the
 * rest would hold the clear value. The casters are kept as boxes around runs
 * of SB_CASTER_RUN triangles (in the world's order, so a run is mostly one
 * object), projected each frame; in a world of more than SB_CASTER_MAX_BOXES
 * runs the runs grow, so that the frame's 4 x 8 corners a box stay a bounded
 * cost (a million triangles would otherwise be a million projections).
 */
#define SB_CASTER_RUN 32
#define SB_CASTER_MAX_BOXES 1024

struct sb_caster_box {
    double min[3], max[3]; /* world, m */
};

/*
 * The far map, which shadows what lies past the last cascade: an
 * orthographic view along the light over the casters' boxes (across) and
 * the world's box (along), fixed in the world, so that it neither swims
 * nor needs drawing as the camera moves; its matrix takes offsets from
 * camera_m as the cascades' do. Returns false with no casters (nothing to
 * draw; every lookup sees the light).
 */
bool sb_far_shadow_compute(const double camera_m[3], const double light[3], const struct sb_caster_box *boxes,
                           unsigned count, const double world_min[3], const double world_max[3], unsigned map_size,
                           struct sb_mat4 *view_proj, double *texel_m, double *depth_m);

/* The boxes of vertices[first, end) (a triangle list; the world's casters).
 * Returns how many, or 0 with *out NULL on no casters or no memory (*out is
 * NULL then; failed set when it was the memory). */
unsigned sb_caster_boxes(const struct sb_vertex_gpu *vertices, uint32_t first, uint32_t end, struct sb_caster_box **out,
                         bool *failed);

/*
 * The texels of a map_size^2 cascade that casters can cover, as the box
 * [rect[0], rect[2]) x [rect[1], rect[3]) of texel indices, from the boxes'
 * corners through view_proj (camera-relative, so camera_m is subtracted):
 * every texel whose centre a projected caster covers is inside. Empty
 * (rect[0] >= rect[2]) when no box reaches the map.
 */
void sb_cascade_caster_rect(const struct sb_mat4 *view_proj, const double camera_m[3],
                            const struct sb_caster_box *boxes, unsigned count, unsigned map_size, int32_t rect[4]);

#endif
