/*
 * The reflection probes' bindings and GPU form (runtime/passes/scene.c,
 * reflections.glsl); config.h's rules.
 */
#ifndef SB_SHADERS_REFLECTIONS_GPU_H
#define SB_SHADERS_REFLECTIONS_GPU_H

#include "config.h"

#define SB_VIEW_BINDING_REFLECTIONS 22   /* struct sb_reflections_gpu, then its probes and the DFG LUT */
#define SB_VIEW_BINDING_REFLECTION_CUBES 23 /* the reflection cubes' texels, vec4 (reflections.glsl) */

/* The reflection probes skyview reads (reflections.glsl): a pack's
 * reflection_cubes in SB_VIEW_BINDING_REFLECTION_CUBES (cube by cube, each
 * its chain level by level, faces as OpenEXR lays them, one vec4 a texel)
 * and, after this header, 3 vec4 a cube (position, box min, box max; the
 * first is the sky-only probe) and the DFG LUT (SB_DFG_SIZE^2 vec4: x, y). */
struct sb_reflections_gpu {
    SB_UVEC4(info);        /* x: face size; y: levels; z: cubes (0: none); w: 1 when the DFG LUT follows */
    SB_VEC4(baked_sun);    /* xyz: the sun the cubes were captured under; w: unused */
    SB_VEC4(baked_sky_up); /* rgb: the sky-only cube's irradiance on an upward surface; w: unused */
    SB_UVEC4(level_offsets[4]); /* each level's first texel in a cube's chain; [3].w: a cube's texels */
};

#endif
