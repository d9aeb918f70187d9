/*
 * Cascaded shadow maps for a camera and the sun: the practical split scheme
 * (a blend of logarithmic and uniform splits, Zhang et al. 2006), one
 * bounding sphere per cascade so a cascade's size does not change as the
 * camera turns, and its centre snapped to whole shadow texels in the sun's
 * frame so shadows do not swim as the camera moves.
 */
#ifndef SB_RUNTIME_SHADOWS_H
#define SB_RUNTIME_SHADOWS_H

#include "config.h"
#include "transform.h"

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

#endif
