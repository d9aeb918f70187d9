/*
 * Analytic test geometry, built through sb_mesh_add_triangle like any
 * procedural source: a closed box, a large plane, a cylindrical well in the
 * ground, a room with one window. Faces wind counter-clockwise seen from
 * outside (the front, as bvh.h counts it); a room's and a well's walls face
 * inward, into the space they enclose. Metres, y up.
 */
#ifndef SB_TEST_SHAPES_H
#define SB_TEST_SHAPES_H

#include <math.h>

#include "mesh.h"

static inline enum sb_result shape_quad(struct sb_mesh *m, const double a[3], const double b[3], const double c[3],
                                        const double d[3], uint32_t material)
{
    enum sb_result res = sb_mesh_add_triangle(m, a, b, c, material, "shape");
    return res ? res : sb_mesh_add_triangle(m, a, c, d, material, "shape");
}

/* An axis-aligned box; faces out (inward: faces in). */
static inline enum sb_result shape_box(struct sb_mesh *m, const double lo[3], const double hi[3], bool inward,
                                       uint32_t material)
{
    double p[8][3];
    for (int i = 0; i < 8; i++) {
        p[i][0] = i & 1 ? hi[0] : lo[0];
        p[i][1] = i & 2 ? hi[1] : lo[1];
        p[i][2] = i & 4 ? hi[2] : lo[2];
    }
    /* each face's corners counter-clockwise seen from outside */
    static const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    enum sb_result res = SB_OK;
    for (int f = 0; f < 6 && !res; f++) {
        const int *q = faces[f];
        res = inward ? shape_quad(m, p[q[0]], p[q[3]], p[q[2]], p[q[1]], material)
                     : shape_quad(m, p[q[0]], p[q[1]], p[q[2]], p[q[3]], material);
    }
    return res;
}

/* A square plane at height y, half-width `half`, facing up. */
static inline enum sb_result shape_plane(struct sb_mesh *m, double y, double half, uint32_t material)
{
    double a[3] = {-half, y, -half}, b[3] = {-half, y, half}, c[3] = {half, y, half}, d[3] = {half, y, -half};
    return shape_quad(m, a, b, c, d, material);
}

/* A well of radius r and depth h (its floor at y = -h), `sides` straight
 * walls (an inscribed polygon), in a ground of half-width `half` at y = 0. */
static inline enum sb_result shape_well(struct sb_mesh *m, double r, double h, int sides, double half,
                                        uint32_t material)
{
    enum sb_result res = SB_OK;
    double far = half * sqrt(2.0) * 1.01;
    for (int i = 0; i < sides && !res; i++) {
        double a0 = 2 * M_PI * i / sides, a1 = 2 * M_PI * (i + 1) / sides;
        double c0 = cos(a0), s0 = sin(a0), c1 = cos(a1), s1 = sin(a1);
        double top0[3] = {r * c0, 0, r * s0}, top1[3] = {r * c1, 0, r * s1};
        double bot0[3] = {r * c0, -h, r * s0}, bot1[3] = {r * c1, -h, r * s1};
        double centre[3] = {0, -h, 0};
        /* the ground: a fan from the rim out to a circle beyond the square */
        double out0[3] = {far * c0, 0, far * s0}, out1[3] = {far * c1, 0, far * s1};
        res = shape_quad(m, top0, top1, out1, out0, material);
        if (!res) /* wall, facing the axis */
            res = shape_quad(m, bot0, bot1, top1, top0, material);
        if (!res) /* floor, facing up */
            res = sb_mesh_add_triangle(m, centre, bot1, bot0, material, "shape");
    }
    return res;
}

/* A closed room [lo, hi] with walls facing in and one window in its +x wall:
 * a hole spanning z in [wz0, wz1] and y in [wy0, wy1]. */
static inline enum sb_result shape_room(struct sb_mesh *m, const double lo[3], const double hi[3], double wz0,
                                        double wz1, double wy0, double wy1, uint32_t material)
{
    struct sb_mesh tmp = {0};
    uint32_t mat;
    double grey[3] = {0.5, 0.5, 0.5};
    enum sb_result res = sb_mesh_add_material(&tmp, "room", grey, &mat);
    if (!res)
        res = shape_box(&tmp, lo, hi, true, mat);
    /* keep every face but the +x wall's two triangles */
    for (uint32_t t = 0; t < tmp.triangle_count && !res; t++) {
        double v[3][3];
        bool plus_x = true;
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 3; i++) {
                v[k][i] = tmp.positions[3 * tmp.indices[3 * t + k] + i];
                if (i == 0)
                    plus_x &= v[k][0] == hi[0];
            }
        if (!plus_x)
            res = sb_mesh_add_triangle(m, v[0], v[1], v[2], material, "shape");
    }
    sb_mesh_finish(&tmp);
    /* the +x wall around the window, facing -x (into the room) */
    double x = hi[0];
    double zs[4] = {lo[2], wz0, wz1, hi[2]}, ys[4] = {lo[1], wy0, wy1, hi[1]};
    for (int i = 0; i < 3 && !res; i++)
        for (int j = 0; j < 3 && !res; j++) {
            if (i == 1 && j == 1)
                continue; /* the window */
            double a[3] = {x, ys[j], zs[i]}, b[3] = {x, ys[j], zs[i + 1]}, c[3] = {x, ys[j + 1], zs[i + 1]},
                   d[3] = {x, ys[j + 1], zs[i]};
            res = shape_quad(m, a, b, c, d, material);
        }
    return res;
}

#endif
