#include "transform.h"

#include <math.h>
#include <string.h>

#define M(a, c, r) ((a)->m[(c)*4 + (r)])

struct sb_mat4 sb_mat4_identity(void)
{
    struct sb_mat4 a = {{0}};
    a.m[0] = a.m[5] = a.m[10] = a.m[15] = 1.0;
    return a;
}

struct sb_mat4 sb_mat4_mul(const struct sb_mat4 *a, const struct sb_mat4 *b)
{
    struct sb_mat4 o;
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += M(a, k, r) * M(b, c, k);
            M(&o, c, r) = s;
        }
    return o;
}

struct sb_mat4 sb_mat4_inverse(const struct sb_mat4 *a)
{
    /* Gauss-Jordan with partial pivoting on [A | I]. */
    double w[4][8];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            w[r][c] = M(a, c, r);
            w[r][4 + c] = r == c ? 1.0 : 0.0;
        }
    for (int col = 0; col < 4; col++) {
        int pivot = col;
        for (int r = col + 1; r < 4; r++)
            if (fabs(w[r][col]) > fabs(w[pivot][col]))
                pivot = r;
        if (w[pivot][col] == 0.0)
            return sb_mat4_identity();
        if (pivot != col)
            for (int c = 0; c < 8; c++) {
                double t = w[col][c];
                w[col][c] = w[pivot][c];
                w[pivot][c] = t;
            }
        double inv = 1.0 / w[col][col];
        for (int c = 0; c < 8; c++)
            w[col][c] *= inv;
        for (int r = 0; r < 4; r++)
            if (r != col && w[r][col] != 0.0) {
                double f = w[r][col];
                for (int c = 0; c < 8; c++)
                    w[r][c] -= f * w[col][c];
            }
    }
    struct sb_mat4 o;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            M(&o, c, r) = w[r][4 + c];
    return o;
}

void sb_mat4_project(const struct sb_mat4 *a, const double p[3], double out[3])
{
    double v[4];
    for (int r = 0; r < 4; r++)
        v[r] = M(a, 0, r) * p[0] + M(a, 1, r) * p[1] + M(a, 2, r) * p[2] + M(a, 3, r);
    for (int i = 0; i < 3; i++)
        out[i] = v[i] / v[3];
}

static void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void normalize(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++)
        v[i] /= n;
}

struct sb_mat4 sb_mat4_look(const double forward[3], const double up[3])
{
    double f[3] = {forward[0], forward[1], forward[2]}, s[3], u[3];
    normalize(f);
    cross(f, up, s);
    normalize(s);
    cross(s, f, u);
    struct sb_mat4 o = sb_mat4_identity();
    for (int c = 0; c < 3; c++) {
        M(&o, c, 0) = s[c];
        M(&o, c, 1) = u[c];
        M(&o, c, 2) = -f[c];
    }
    return o;
}

struct sb_mat4 sb_mat4_perspective(double fov_y, double aspect, double near)
{
    double f = 1.0 / tan(0.5 * fov_y);
    struct sb_mat4 o = {{0}};
    M(&o, 0, 0) = f / aspect;
    M(&o, 1, 1) = -f; /* Vulkan's clip y points down */
    M(&o, 3, 2) = near;
    M(&o, 2, 3) = -1.0;
    return o;
}

struct sb_mat4 sb_mat4_ortho(double half, double near, double far)
{
    struct sb_mat4 o = sb_mat4_identity();
    M(&o, 0, 0) = 1.0 / half;
    M(&o, 1, 1) = 1.0 / half;
    M(&o, 2, 2) = -1.0 / (far - near);
    M(&o, 3, 2) = -near / (far - near);
    return o;
}

struct sb_mat4 sb_mat4_translate(const double t[3])
{
    struct sb_mat4 o = sb_mat4_identity();
    for (int i = 0; i < 3; i++)
        M(&o, 3, i) = t[i];
    return o;
}

void sb_mat4_store(const struct sb_mat4 *a, float out[16])
{
    for (int i = 0; i < 16; i++)
        out[i] = (float)a->m[i];
}

void sb_direction(double azimuth, double elevation, double out[3])
{
    out[0] = cos(elevation) * sin(azimuth);
    out[1] = sin(elevation);
    out[2] = -cos(elevation) * cos(azimuth);
}
