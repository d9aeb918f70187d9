/*
 * The sky-visibility probes' bindings and GPU form (runtime/passes/probes.c,
 * probes.glsl); the scene and the fog read them too. config.h's rules.
 */
#ifndef SB_SHADERS_PROBES_GPU_H
#define SB_SHADERS_PROBES_GPU_H

#include "config.h"

#define SB_VIEW_BINDING_PROBES 20        /* struct sb_probes_gpu, then SB_PROBE_VEC4S vec4s a probe */
#define SB_VIEW_BINDING_PROBE_LIGHT 21   /* the sky's SH, then each probe's irradiance SH (probes.glsl) */
#define SB_VIEW_BINDING_PROBE_DETAIL 56  /* the detail's brick columns, uvec4 each (probes.glsl) */
#define SB_VIEW_BINDING_PROBE_SIGHT 57   /* the detail probes' sight masks, config.h's SB_PROBE_SIGHT_* */

/* The sky-visibility probes skyview lights the world with (probes.glsl):
 * the grid of a pack's sky_visibility product, and the SH triple-product
 * tensor's non-zero entries (sb_sh9_tensor). probe_sky.comp projects the
 * sky's radiance on SH over SB_PROBE_SKY_DIRECTIONS directions, one
 * workgroup of SB_PROBE_SKY_THREADS; probe_light.comp relights each probe,
 * SB_PROBE_THREADS a workgroup. */
#define SB_SH_TENSOR_MAX 128 /* 83 are not zero */
#define SB_PROBE_SKY_THREADS 64
#define SB_PROBE_SKY_DIRECTIONS 4096
#define SB_PROBE_BRICK 4 /* lattice columns across a brick column (SB_PROBES_BRICK) */
struct sb_probes_gpu {
    SB_UVEC4(grid);          /* xyz: probes along each axis; w: grid probes (0: none, the sky-only ambient) */
    SB_VEC4(origin_m);       /* xyz: the first probe (world, m); w: tensor entries */
    SB_VEC4(spacing_m);      /* xyz: between probes; w: 1 when the pack's sky_bounce is in probe_data */
    SB_VEC4(bounce_albedo);  /* rgb: the world's mean albedo by area (the bounce model); w: unused */
    /* A grid whose layers follow the surface (formats/probes.h): x its
     * layer count (grid.y; 0: a uniform grid), and each layer's height
     * over the surface under its column (m), 4 a vec4; each probe's 4th
     * vec4 holds its column's surface height in y. */
    SB_UVEC4(layered);
    SB_VEC4(layers_m[2]);
    /* Detail (formats/probes.h): a table of x by y brick columns over the
     * lattice (z: 1 when the detail probes' sight masks are bound; w:
     * the columns present, 0: no detail), the lattice's first probe (xyz,
     * m) and spacing (w). A column's entry: its lowest row, its rows (0:
     * absent), its first probe's index, and that among the detail probes
     * (its first sight mask's). */
    SB_UVEC4(detail);
    SB_VEC4(detail_origin_m);
    SB_VEC4(tensor[SB_SH_TENSOR_MAX]); /* x: the integral of Y_i Y_j Y_k; y, z, w: i, j, k */
};

#endif
