#include "sky_bounce_ref.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sh.h"
#include "splitmix.h"

/* A path: where it goes next, what it carries, what it has gathered. */
struct path {
    double origin[3], dir[3], first[3];
    double carried[3]; /* the product of the albedos met (over the roulette's odds) */
    double light[3];   /* radiance gathered along the first direction */
    uint64_t rng;
    uint32_t surfaces; /* met so far */
    bool alive, direct; /* direct: its first ray saw the sky */
};

void sb_bounce_ref_normal(int i, double n[3])
{
    n[0] = n[1] = n[2] = 0;
    n[i / 2] = i % 2 ? -1.0 : 1.0;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* A direction about unit n, cosine-distributed (Duff et al.'s basis). */
static void cosine_about(const double n[3], uint64_t *rng, double d[3])
{
    double sign = copysign(1.0, n[2]), a = -1.0 / (sign + n[2]), b = n[0] * n[1] * a;
    double t[3] = {1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]};
    double u[3] = {b, sign + n[1] * n[1] * a, -n[1]};
    double r1 = sb_splitmix_uniform(rng), r2 = sb_splitmix_uniform(rng), r = sqrt(r1), phi = 2 * M_PI * r2, z = sqrt(fmax(0.0, 1 - r1));
    for (int k = 0; k < 3; k++)
        d[k] = r * cos(phi) * t[k] + r * sin(phi) * u[k] + z * n[k];
}

static void sky_radiance(const struct sb_bounce_lighting *light, const double d[3], double out[3])
{
    double y[SB_PROBE_SH];
    sb_sh9_basis(d, y);
    for (int c = 0; c < 3; c++) {
        out[c] = 0;
        for (int k = 0; k < SB_PROBE_SH; k++)
            out[c] += light->sky[k][c] * y[k];
    }
}

static void set_ray(float *ray, const double origin[3], const double dir[3], double tmin)
{
    for (int k = 0; k < 3; k++) {
        ray[k] = (float)origin[k];
        ray[4 + k] = (float)dir[k];
    }
    ray[3] = (float)tmin;
    ray[7] = 1e30f;
}

/* The paths of one point, as waves of rays: each wave casts every live
 * path's next ray, then a shadow ray toward the sun from each surface met. */
static bool trace_point(const struct sb_mesh *mesh, const struct sb_embree *e, const double point[3],
                        const struct sb_bounce_lighting *light, uint32_t paths, uint32_t bounces, uint64_t seed,
                        struct sb_bounce_irradiance *out)
{
    struct path *p = calloc(paths, sizeof(*p));
    float *rays = malloc(sizeof(float) * 8 * paths), *hits = malloc(sizeof(float) * 4 * paths);
    float *shadow = malloc(sizeof(float) * 8 * paths), *shadow_hits = malloc(sizeof(float) * 4 * paths);
    uint32_t *owner = malloc(sizeof(uint32_t) * paths), *shadow_owner = malloc(sizeof(uint32_t) * paths);
    double(*gain)[3] = malloc(sizeof(double) * 3 * paths);
    bool ok = p && rays && hits && shadow && shadow_hits && owner && shadow_owner && gain;
    for (uint32_t i = 0; ok && i < paths; i++) {
        struct path *q = &p[i];
        q->rng = seed ^ (0x632be59bd9b4e019ull * (i + 1));
        double z = 1 - 2 * sb_splitmix_uniform(&q->rng), phi = 2 * M_PI * sb_splitmix_uniform(&q->rng), r = sqrt(fmax(0.0, 1 - z * z));
        double d[3] = {r * cos(phi), z, r * sin(phi)};
        memcpy(q->origin, point, sizeof(q->origin));
        memcpy(q->dir, d, sizeof(q->dir));
        memcpy(q->first, d, sizeof(q->first));
        q->carried[0] = q->carried[1] = q->carried[2] = 1;
        q->alive = true;
    }
    for (uint32_t wave = 0; ok; wave++) {
        uint32_t live = 0;
        for (uint32_t i = 0; i < paths; i++)
            if (p[i].alive) {
                set_ray(&rays[8 * live], p[i].origin, p[i].dir, wave ? 0.0 : 1e-4);
                owner[live++] = i;
            }
        if (!live)
            break;
        sb_embree_cast(e, rays, live, hits);
        uint32_t shadows = 0;
        for (uint32_t r = 0; r < live; r++) {
            struct path *q = &p[owner[r]];
            uint32_t t;
            memcpy(&t, &hits[4 * r + 1], sizeof(t));
            if (t == SB_BVH_MISS) {
                double sky[3];
                sky_radiance(light, q->dir, sky);
                for (int c = 0; c < 3; c++)
                    q->light[c] += q->carried[c] * sky[c];
                q->direct = q->surfaces == 0;
                q->alive = false;
                continue;
            }
            if (bounces && q->surfaces >= bounces) {
                q->alive = false;
                continue;
            }
            q->surfaces++;
            t &= ~SB_BVH_BACK_FACE;
            double pos[3][3], e1[3], e2[3], n[3], x[3], big = 0;
            for (int v = 0; v < 3; v++)
                for (int k = 0; k < 3; k++)
                    pos[v][k] = mesh->positions[3 * mesh->indices[3 * t + v] + k];
            for (int k = 0; k < 3; k++) {
                e1[k] = pos[1][k] - pos[0][k];
                e2[k] = pos[2][k] - pos[0][k];
            }
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            double len = sqrt(dot3(n, n)), side = dot3(n, q->dir) > 0 ? -1.0 : 1.0;
            for (int k = 0; k < 3; k++) {
                n[k] *= side / len;
                x[k] = q->origin[k] + q->dir[k] * hits[4 * r];
                big = fmax(big, fabs(x[k]));
            }
            double eps = 1e-4 + 2e-6 * big;
            for (int k = 0; k < 3; k++)
                q->origin[k] = x[k] + n[k] * eps;
            const float *rho = mesh->material_list[mesh->materials[t]].albedo;
            double c_sun = dot3(n, light->sun_dir);
            if (c_sun > 0) { /* the sun, if the shadow ray escapes */
                set_ray(&shadow[8 * shadows], q->origin, light->sun_dir, eps);
                for (int c = 0; c < 3; c++)
                    gain[shadows][c] = q->carried[c] * rho[c] / M_PI * light->sun[c] * c_sun;
                shadow_owner[shadows++] = owner[r];
            }
            for (int c = 0; c < 3; c++)
                q->carried[c] *= rho[c];
            cosine_about(n, &q->rng, q->dir);
            /* past the second surface, Russian roulette on the albedo */
            double keep = fmin(0.95, fmax(rho[0], fmax(rho[1], rho[2])));
            if (q->surfaces >= 2) {
                if (sb_splitmix_uniform(&q->rng) >= keep)
                    q->alive = false;
                else
                    for (int c = 0; c < 3; c++)
                        q->carried[c] /= keep;
            }
            if (!(keep > 0))
                q->alive = false;
        }
        if (shadows) {
            sb_embree_cast(e, shadow, shadows, shadow_hits);
            for (uint32_t s = 0; s < shadows; s++) {
                uint32_t t;
                memcpy(&t, &shadow_hits[4 * s + 1], sizeof(t));
                if (t == SB_BVH_MISS)
                    for (int c = 0; c < 3; c++)
                        p[shadow_owner[s]].light[c] += gain[s][c];
            }
        }
    }
    if (ok) {
        /* irradiance about each normal: 4 pi / paths sum L (n . w)+, and
         * the standard error of that mean */
        double sum[2][SB_BOUNCE_REF_NORMALS][3] = {{{0}}}, squares[2][SB_BOUNCE_REF_NORMALS][3] = {{{0}}};
        double mean[3] = {0}, mean_squares[3] = {0};
        for (uint32_t i = 0; i < paths; i++) {
            /* the mean over the 6 axes of (n . w)+ is (|x| + |y| + |z|) / 6 */
            const double *w = p[i].first;
            double all = (fabs(w[0]) + fabs(w[1]) + fabs(w[2])) / 6 * 4 * M_PI *
                         (p[i].light[0] + p[i].light[1] + p[i].light[2]);
            double part[3] = {p[i].direct ? all : 0, p[i].direct ? 0 : all, all};
            for (int s = 0; s < 3; s++) {
                mean[s] += part[s];
                mean_squares[s] += part[s] * part[s];
            }
            for (int k = 0; k < SB_BOUNCE_REF_NORMALS; k++) {
                double n[3];
                sb_bounce_ref_normal(k, n);
                double c = fmax(0.0, dot3(n, p[i].first)) * 4 * M_PI;
                for (int ch = 0; ch < 3; ch++) {
                    double v = c * p[i].light[ch];
                    sum[!p[i].direct][k][ch] += v;
                    squares[!p[i].direct][k][ch] += v * v;
                }
            }
        }
        for (int s = 0; s < 3; s++) {
            out->mean[s] = mean[s] / paths;
            out->mean_error[s] = sqrt(fmax(0.0, mean_squares[s] / paths - out->mean[s] * out->mean[s]) / paths);
        }
        for (int s = 0; s < 2; s++)
            for (int k = 0; k < SB_BOUNCE_REF_NORMALS; k++)
                for (int ch = 0; ch < 3; ch++) {
                    double m = sum[s][k][ch] / paths;
                    double se = sqrt(fmax(0.0, squares[s][k][ch] / paths - m * m) / paths);
                    (s ? out->bounced : out->sky)[k][ch] = m;
                    (s ? out->bounced_error : out->sky_error)[k][ch] = se;
                }
    }
    free(p);
    free(rays);
    free(hits);
    free(shadow);
    free(shadow_hits);
    free(owner);
    free(shadow_owner);
    free(gain);
    return ok;
}

bool sb_bounce_path_trace(const struct sb_mesh *mesh, const struct sb_embree *e, const double *points,
                          uint32_t count, const struct sb_bounce_lighting *light, uint32_t paths, uint32_t bounces,
                          uint64_t seed, struct sb_bounce_irradiance *out)
{
    for (uint32_t m = 0; m < mesh->material_count; m++)
        if (mesh->material_list[m].textures[0] >= 0)
            return false;
    for (uint32_t i = 0; i < count; i++) {
        memset(&out[i], 0, sizeof(out[i]));
        if (!trace_point(mesh, e, &points[3 * i], light, paths, bounces, seed + 0x9e3779b97f4a7c15ull * i, &out[i]))
            return false;
    }
    return true;
}
