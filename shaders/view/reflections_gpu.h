/*
 * The reflection probes' bindings and GPU form (runtime/passes/scene.c,
 * reflections.glsl); config.h's rules.
 */
#ifndef SB_SHADERS_REFLECTIONS_GPU_H
#define SB_SHADERS_REFLECTIONS_GPU_H

#include "config.h"

#define SB_VIEW_BINDING_REFLECTIONS 22   /* struct sb_reflections_gpu, then its probes and the DFG LUT */
#define SB_VIEW_BINDING_REFLECTION_CUBES 23 /* the reflection cubes' texels, vec4 (reflections.glsl) */
#define SB_VIEW_BINDING_REFLECTION_SURFACES 62 /* the pack's reflection_surfaces, level 0, SB_RELIGHT_VEC4S a texel */
#define SB_VIEW_BINDING_REFLECTION_CHAIN 63    /* a relit cube's box-filtered chain, vec4 a texel */
#define SB_VIEW_BINDING_RELIGHT 64             /* struct sb_relight_gpu */
#define SB_RELIGHT_THREADS 64                  /* reflection_relight.comp's and reflection_chain.comp's workgroup */

/* The reflection probes skyview reads (reflections.glsl): a pack's
 * reflection_cubes in SB_VIEW_BINDING_REFLECTION_CUBES (cube by cube, each
 * its chain level by level, faces as OpenEXR lays them, one vec4 a texel)
 * and, after this header, 3 vec4 a cube (position, box min, box max; the
 * first is the sky-only probe) and the DFG LUT (SB_DFG_SIZE^2 vec4: x, y). */
struct sb_reflections_gpu {
    SB_UVEC4(info);        /* x: face size; y: levels; z: cubes (0: none); w: 1 when the DFG LUT follows */
    SB_VEC4(baked_sun);    /* xyz: the sun the cubes were captured under; w: 1 when skyview relights them */
    SB_VEC4(baked_sky_up); /* rgb: the sky-only cube's irradiance on an upward surface; w: unused */
    SB_UVEC4(level_offsets[4]); /* each level's first texel in a cube's chain; [3].w: a cube's texels */
};

/* How skyview relights a cube (runtime/passes/reflections.c): level 0
 * from the pack's surfaces (reflection_relight.comp), its box chain
 * (reflection_chain.comp), then each level's GGX prefilter as the bake's
 * (reflection_filter.comp, prefilter.glsl), per level l >= 1 laid out by
 * sb_prefilter_layout. */
#define SB_RELIGHT_MAX_LEVELS 16
struct sb_relight_gpu {
    SB_UVEC4(level[SB_RELIGHT_MAX_LEVELS]); /* samples, threads_per_texel, groups_x, the roughness's bits */
};

#endif
