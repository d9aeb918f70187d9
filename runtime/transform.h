/*
 * 4x4 transforms in double precision, column-major like GLSL (element at
 * column c, row r is m[c * 4 + r]), for the camera and the shadow cascades.
 * View space is right-handed, looking down -z with y up; clip space is
 * Vulkan's (y down, depth in [0, 1]).
 */
#ifndef SB_RUNTIME_TRANSFORM_H
#define SB_RUNTIME_TRANSFORM_H

struct sb_mat4 {
    double m[16];
};

struct sb_mat4 sb_mat4_identity(void);
struct sb_mat4 sb_mat4_mul(const struct sb_mat4 *a, const struct sb_mat4 *b);
/* The inverse; the identity when the matrix is singular. */
struct sb_mat4 sb_mat4_inverse(const struct sb_mat4 *a);
/* A point through the matrix, divided by w. */
void sb_mat4_project(const struct sb_mat4 *a, const double p[3], double out[3]);

/* World to view for an eye at the origin looking along unit `forward`, with
 * `up` the reference up (not parallel to forward). */
struct sb_mat4 sb_mat4_look(const double forward[3], const double up[3]);
/* Perspective with reverse Z and an infinite far plane: depth near / distance,
 * 1 at the near plane, 0 at infinity. fov_y in radians. */
struct sb_mat4 sb_mat4_perspective(double fov_y, double aspect, double near);
/* Orthographic: x in [-half, half] and y likewise to [-1, 1]; view depth
 * (-z) in [near, far] to [0, 1]. */
struct sb_mat4 sb_mat4_ortho(double half, double near, double far);
/* A translation by t. */
struct sb_mat4 sb_mat4_translate(const double t[3]);

/* Copy to the fp32 layout the shaders read. */
void sb_mat4_store(const struct sb_mat4 *a, float out[16]);

/* Unit vector from an azimuth (clockwise from -z toward +x, radians) and an
 * elevation above the horizontal (radians): north is -z, east +x, up +y. */
void sb_direction(double azimuth, double elevation, double out[3]);

#endif
