/*
 * Cube-map geometry, the C twin of shaders/cube.glsl: OpenEXR's layout
 * (face f of an N x 6N image is rows [f N, (f + 1) N); faces +x, -x, +y,
 * -y, +z, -z; u along a row, v down the rows, in [-1, 1]), texel
 * directions and exact solid angles, and box-filtered mip chains.
 */
#ifndef SB_BAKER_CUBE_H
#define SB_BAKER_CUBE_H

#include <stdint.h>

/* The (unnormalised) direction of (u, v) on `face`. */
void sb_cube_direction(int face, double u, double v, double out[3]);

/* The unit direction through the centre of texel (x, y) of a face of n. */
void sb_cube_texel_direction(int face, uint32_t n, uint32_t x, uint32_t y, double out[3]);

/* The face a direction is in and its (u, v) there. */
int sb_cube_face(const double d[3], double *u, double *v);

/* The solid angle of the rectangle [u0, u1] x [v0, v1] of a face. */
double sb_cube_solid_angle(double u0, double v0, double u1, double v1);

/* One face of n x n texels, `stride` floats apart (rgb first), read at
 * (u, v) bilinearly between texel centres and clamped at the face's edges:
 * how the device reads a cube (reflection_prefilter.comp, reflections.glsl). */
void sb_cube_bilinear(const float *face, uint32_t n, uint32_t stride, double u, double v, double out[3]);

/* Texels before level `level` in one cube's chain (6 faces a level). */
uint64_t sb_cube_level_offset(uint32_t face_size, uint32_t level);

/* Fill levels 1.. of a chain of rgba texels (level 0 given) by 2 x 2 box
 * filtering in fp64 (a texel's w is the mean of its children's too). */
void sb_cube_build_mips(float *chain, uint32_t face_size, uint32_t levels);

#endif
