/*
 * The prefilter's fp64 reference (reflection.h): dense integration of the
 * GGX lobe over every texel of the source cube, each split into sub x sub
 * pieces with their exact solid angles, the radiance read bilinearly
 * within the face (texel centres, clamped at its edges) as the device
 * reads its level 0.
 */
#include <math.h>

#include "cube.h"
#include "reflection.h"

void sb_reflection_reference(const float *level0, uint32_t n, const double nd[3], double r, int sub, double out[3])
{
    if (r <= 0) {
        double u, v;
        int face = sb_cube_face(nd, &u, &v);
        sb_cube_bilinear(level0 + 4 * (size_t)face * n * n, n, 4, u, v, out);
        return;
    }
    double a2 = r * r * r * r;
    /* Past tan theta_h = 100 alpha, D is below 1e-8 of its peak: what lies
     * there weighs under 2e-4 of the lobe even over a whole hemisphere. */
    double t2 = 1e4 * a2, nl_min = fmax(2.0 / (1.0 + t2) - 1.0, 0.0);
    double sum[3] = {0, 0, 0}, weight = 0;
    uint32_t m = n * (uint32_t)sub;
    double step = 2.0 / m;
    for (int f = 0; f < 6; f++)
        for (uint32_t y = 0; y < m; y++)
            for (uint32_t x = 0; x < m; x++) {
                double u0 = -1 + x * step, v0 = -1 + y * step, u = u0 + 0.5 * step, v = v0 + 0.5 * step;
                double l[3];
                sb_cube_direction(f, u, v, l);
                double len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
                double nl = (nd[0] * l[0] + nd[1] * l[1] + nd[2] * l[2]) / len;
                if (nl <= nl_min)
                    continue;
                /* n.h with h = normalize(n + l): cos^2 = (1 + n.l) / 2 */
                double c2 = 0.5 * (1 + nl), d = c2 * (a2 - 1) + 1;
                double w = a2 / (M_PI * d * d) * nl * sb_cube_solid_angle(u0, v0, u0 + step, v0 + step);
                double L[3];
                sb_cube_bilinear(level0 + 4 * (size_t)f * n * n, n, 4, u, v, L);
                for (int c = 0; c < 3; c++)
                    sum[c] += w * L[c];
                weight += w;
            }
    for (int c = 0; c < 3; c++)
        out[c] = weight > 0 ? sum[c] / weight : 0;
}
