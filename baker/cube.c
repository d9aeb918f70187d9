#include "cube.h"

#include <math.h>
#include <stddef.h>

void sb_cube_direction(int face, double u, double v, double out[3])
{
    const double d[6][3] = {{1, -v, u}, {-1, -v, -u}, {u, 1, -v}, {u, -1, v}, {-u, -v, 1}, {u, -v, -1}};
    for (int k = 0; k < 3; k++)
        out[k] = d[face][k];
}

void sb_cube_texel_direction(int face, uint32_t n, uint32_t x, uint32_t y, double out[3])
{
    sb_cube_direction(face, (x + 0.5) / n * 2.0 - 1.0, (y + 0.5) / n * 2.0 - 1.0, out);
    double len = sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
    for (int k = 0; k < 3; k++)
        out[k] /= len;
}

int sb_cube_face(const double d[3], double *u, double *v)
{
    double ax = fabs(d[0]), ay = fabs(d[1]), az = fabs(d[2]);
    if (ax >= ay && ax >= az) {
        *u = (d[0] > 0 ? d[2] : -d[2]) / ax;
        *v = -d[1] / ax;
        return d[0] > 0 ? 0 : 1;
    }
    if (ay >= az) {
        *u = d[0] / ay;
        *v = (d[1] > 0 ? -d[2] : d[2]) / ay;
        return d[1] > 0 ? 2 : 3;
    }
    *u = (d[2] > 0 ? -d[0] : d[0]) / az;
    *v = -d[1] / az;
    return d[2] > 0 ? 4 : 5;
}

/* The solid angle of [0, u] x [0, v] on a face at distance 1. */
static double corner_area(double u, double v)
{
    return atan2(u * v, sqrt(u * u + v * v + 1.0));
}

double sb_cube_solid_angle(double u0, double v0, double u1, double v1)
{
    return corner_area(u1, v1) - corner_area(u0, v1) - corner_area(u1, v0) + corner_area(u0, v0);
}

void sb_cube_bilinear(const float *face, uint32_t n, uint32_t stride, double u, double v, double out[3])
{
    double px = fmin(fmax((u * 0.5 + 0.5) * n - 0.5, 0.0), n - 1.0);
    double py = fmin(fmax((v * 0.5 + 0.5) * n - 0.5, 0.0), n - 1.0);
    uint32_t x0 = (uint32_t)px, y0 = (uint32_t)py;
    uint32_t x1 = x0 + 1 < n ? x0 + 1 : n - 1, y1 = y0 + 1 < n ? y0 + 1 : n - 1;
    double fx = px - x0, fy = py - y0;
    for (int c = 0; c < 3; c++) {
        double a = face[stride * ((size_t)y0 * n + x0) + c], b = face[stride * ((size_t)y0 * n + x1) + c];
        double d = face[stride * ((size_t)y1 * n + x0) + c], e = face[stride * ((size_t)y1 * n + x1) + c];
        out[c] = (a + (b - a) * fx) * (1 - fy) + (d + (e - d) * fx) * fy;
    }
}

uint64_t sb_cube_level_offset(uint32_t face_size, uint32_t level)
{
    uint64_t n = 0;
    for (uint32_t l = 0; l < level; l++) {
        uint64_t s = face_size >> l ? face_size >> l : 1;
        n += 6 * s * s;
    }
    return n;
}

void sb_cube_build_mips(float *chain, uint32_t face_size, uint32_t levels)
{
    for (uint32_t l = 1; l < levels; l++) {
        uint32_t n = face_size >> l, m = n * 2;
        const float *src = chain + 4 * sb_cube_level_offset(face_size, l - 1);
        float *dst = chain + 4 * sb_cube_level_offset(face_size, l);
        for (uint32_t f = 0; f < 6; f++)
            for (uint32_t y = 0; y < n; y++)
                for (uint32_t x = 0; x < n; x++)
                    for (int c = 0; c < 4; c++) {
                        const float *s = src + 4 * ((size_t)f * m * m + (size_t)2 * y * m + 2 * x) + c;
                        double sum = (double)s[0] + s[4] + s[4 * m] + s[4 * m + 4];
                        dst[4 * ((size_t)f * n * n + (size_t)y * n + x) + c] = (float)(0.25 * sum);
                    }
    }
}
