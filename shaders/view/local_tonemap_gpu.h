/*
 * Local tone mapping's bindings and parameters
 * (runtime/passes/local_tonemap.c, local_tonemap.glsl); config.h's rules.
 */
#ifndef SB_SHADERS_LOCAL_TONEMAP_GPU_H
#define SB_SHADERS_LOCAL_TONEMAP_GPU_H

#include "config.h"

#define SB_VIEW_BINDING_LOCAL_TONEMAP 49    /* struct sb_local_tonemap_gpu (local_tonemap.glsl) */
#define SB_VIEW_BINDING_LOCAL_TONEMAP_GRID 50 /* its bilateral grid (local_tonemap.glsl) */

/* Local tone mapping (runtime/passes/local_tonemap.c, local_tonemap.glsl): a
 * bilateral grid of the exposed frame's log2 luminance, SB_LTM_GRID_X
 * cells across (square, whole pixels), SB_LTM_BINS bins from SB_LTM_MIN_EV
 * to SB_LTM_MAX_EV; sums in fixed point, 1 / SB_LTM_Q EV, offset by
 * SB_LTM_BIAS so that they are never negative. */
#define SB_LTM_GRID_X 32
#define SB_LTM_BINS 32
#define SB_LTM_MIN_EV -15.0
#define SB_LTM_MAX_EV 9.0
#define SB_LTM_Q 64
#define SB_LTM_BIAS 1024
struct sb_local_tonemap_gpu {
    SB_UVEC4(grid);  /* xyz: cells; w: a cell's side in pixels */
    SB_VEC4(params); /* x: the base layer's contrast (1: none); yzw: unused */
    SB_UVEC4(pivot); /* this frame's: x: the sum of the cells' biased mean log2 luminance, y: the cells with
                        pixels (their mean of means is the pivot); zw: unused */
};

#endif
