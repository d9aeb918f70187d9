/*
 * Colour grading's bindings and parameters (runtime/grading.c,
 * runtime/passes/grade_linear.c and grade.c, lut3d.glsl); config.h's rules.
 */
#ifndef SB_SHADERS_GRADING_GPU_H
#define SB_SHADERS_GRADING_GPU_H

#include "config.h"

#define SB_VIEW_BINDING_GRADE_LUT 46        /* the grading LUT (grade.comp): domain, size, entries */
#define SB_VIEW_BINDING_GRADING 47          /* struct sb_grading_gpu (grade_linear.comp) */

/* Scene-linear grading (runtime/grading.c, passes/grade_linear.c, grade_linear.comp), on the
 * exposed frame before bloom and the tone curve: c = matrix * c (white
 * balance, then saturation), then each channel pivot * (c / pivot)^contrast,
 * then, with a LUT in ACEScct, the LUT. */
struct sb_grading_gpu {
    SB_VEC4(matrix[3]);   /* rows of the 3x3 colour matrix, linear Rec.709 */
    SB_VEC4(tone);        /* x: contrast (an exponent), y: pivot (exposed), zw: unused */
    SB_VEC4(to_ap1[3]);   /* rows: linear Rec.709 (D65) to ACES AP1 (D60), Bradford */
    SB_VEC4(from_ap1[3]); /* rows: its inverse */
};

#endif
