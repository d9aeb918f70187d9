/*
 * The Purkinje shift's binding and parameters (runtime/passes/purkinje.c);
 * config.h's rules.
 */
#ifndef SB_SHADERS_PURKINJE_GPU_H
#define SB_SHADERS_PURKINJE_GPU_H

#include "config.h"

#define SB_VIEW_BINDING_PURKINJE 48         /* struct sb_purkinje_gpu (purkinje.comp) */

/* The Purkinje shift (runtime/passes/purkinje.c, purkinje.comp). */
struct sb_purkinje_gpu {
    SB_VEC4(scale); /* x: cd/m^2 per unit of stored radiance, y: its inverse,
                       z: photopic luminance (cd/m^2, no shift at or above),
                       w: scotopic luminance (the whole shift at or below) */
};

#endif
