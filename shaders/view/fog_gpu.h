/*
 * The froxel fog's bindings and parameters (runtime/passes/fog.c and
 * fog_apply.c, fog.glsl); config.h's rules.
 */
#ifndef SB_SHADERS_FOG_GPU_H
#define SB_SHADERS_FOG_GPU_H

#include "config.h"

#define SB_VIEW_BINDING_FOG 24             /* struct sb_fog_gpu (fog.glsl) */
#define SB_VIEW_BINDING_FROXEL_LIGHT_OUT 25 /* image3D rgba16f: each froxel's scattering (rgb) and extinction */
#define SB_VIEW_BINDING_FROXEL_HISTORY 26   /* sampler3D: the same, the last frame's */
#define SB_VIEW_BINDING_FROXEL_OUT 27       /* image3D rgba16f: in-scattering (rgb) and transmittance to each slice's end */
#define SB_VIEW_BINDING_FROXEL 28           /* sampler3D: the same, read */
#define SB_VIEW_BINDING_FOG_NOISE 29        /* sampler3D, repeating: the pack's cloud_detail (or 1 texel of 1) */

/* The froxel fog (fog.glsl; runtime/passes/fog.c): a camera-aligned volume of
 * froxels, slice w in [0, 1] at distance c ((1 + far / c)^w - 1) along each
 * view ray, lit by fog_inject.comp in 4 x 4 x 4 workgroups and integrated
 * front to back by fog_integrate.comp, one invocation a column in
 * SB_WORKGROUP_X x SB_WORKGROUP_Y. */
#define SB_FOG_VOLUMES 16 /* local fog boxes (SB_FOG_MAX_VOLUMES in scene.h) */
#define SB_FOG_GROUP 4
struct sb_fog_gpu {
    SB_MAT4(previous_view_proj); /* the last frame's camera-relative world to clip */
    SB_UVEC4(grid);              /* xyz: froxels; w: fog volumes */
    SB_VEC4(slices);             /* x: far distance (m); y: c (m); z: log2(1 + far / c); w: history weight */
    SB_VEC4(medium);             /* x: height fog's extinction at its base (1/m); y: base (world y, m);
                                    z: 1 / falloff height (1/m); w: Henyey-Greenstein g */
    SB_VEC4(albedo);             /* rgb: single-scattering albedo; w: noise amount (0: none) */
    SB_VEC4(noise);              /* xyz: the noise's drift (m); w: 1 / its tile (1/m) */
    SB_VEC4(jitter);             /* xyz: this frame's sample in a froxel, [0, 1)^3; w: 1 for the height
                                    fog beyond the volume (the apply pass's tail) */
    SB_VEC4(camera_motion_m);    /* xyz: this frame's camera minus the last frame's (m); w: this frame's
                                    radiance scale over the last's (the history's rgb times it) */
    SB_VEC4(volume_min[SB_FOG_VOLUMES]); /* xyz: a box's min corner (world, m); w: its extinction (1/m) */
    SB_VEC4(volume_max[SB_FOG_VOLUMES]); /* xyz: its max corner; w: its edge (m) */
};

#endif
