#include "shadows.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void sb_cascades_compute(const struct sb_cascade_params *p, const double camera_m[3], const double forward[3],
                         const double sun[3], struct sb_cascades *out)
{
    double n = p->near_m, f = p->distance_m;
    double tan_y = tan(0.5 * p->fov_y), tan_x = tan_y * p->aspect;
    double diag2 = tan_x * tan_x + tan_y * tan_y; /* squared slope of the frustum's corner rays */
    /* The sun's frame: any up that is not parallel to it. */
    double ref_up[3] = {0.0, 1.0, 0.0};
    if (fabs(sun[1]) > 0.99) {
        ref_up[1] = 0.0;
        ref_up[2] = 1.0;
    }
    double toward_ground[3] = {-sun[0], -sun[1], -sun[2]};
    struct sb_mat4 light = sb_mat4_look(toward_ground, ref_up);

    double begin = n;
    for (int i = 0; i < SB_CASCADES; i++) {
        double t = (double)(i + 1) / SB_CASCADES;
        double end = p->lambda * n * pow(f / n, t) + (1.0 - p->lambda) * (n + (f - n) * t);
        out->ends_m[i] = end;
        /* Smallest sphere around the slice [begin, end] of the frustum: its
         * centre on the axis at depth z minimises the larger of the distances
         * to the near and far corner rings; it depends only on the
         * projection, so the cascade keeps its size as the camera turns. */
        double z = 0.5 * (begin + end) * (1.0 + diag2);
        if (z > end)
            z = end;
        double dn = sqrt((z - begin) * (z - begin) + begin * begin * diag2);
        double df = sqrt((end - z) * (end - z) + end * end * diag2);
        double radius = fmax(dn, df);
        radius = ceil(radius * 16.0) / 16.0; /* whole sixteenths: no jitter from rounding */
        double texel = 2.0 * radius / p->map_size;
        out->radius_m[i] = radius;
        out->texel_m[i] = texel;

        /* The centre in the world, snapped to the texel grid of the sun's frame. */
        double centre[3], centre_light[3], snapped[3];
        for (int k = 0; k < 3; k++)
            centre[k] = camera_m[k] + forward[k] * z;
        sb_mat4_project(&light, centre, centre_light);
        snapped[0] = floor(centre_light[0] / texel) * texel;
        snapped[1] = floor(centre_light[1] / texel) * texel;
        snapped[2] = centre_light[2];
        /* The light frame's view matrix is a rotation, so its inverse is the transpose. */
        double world[3];
        for (int k = 0; k < 3; k++)
            world[k] =
                light.m[k * 4 + 0] * snapped[0] + light.m[k * 4 + 1] * snapped[1] + light.m[k * 4 + 2] * snapped[2];
        /* camera-relative -> centred on the snapped centre -> sun's frame -> clip */
        double shift[3] = {camera_m[0] - world[0], camera_m[1] - world[1], camera_m[2] - world[2]};
        struct sb_mat4 to_centre = sb_mat4_translate(shift);
        struct sb_mat4 ortho = sb_mat4_ortho(radius, -(radius + p->caster_margin_m), radius);
        struct sb_mat4 view = sb_mat4_mul(&light, &to_centre);
        out->view_proj[i] = sb_mat4_mul(&ortho, &view);
        begin = end;
    }
}

unsigned sb_caster_boxes(const struct sb_vertex_gpu *vertices, uint32_t first, uint32_t end, struct sb_caster_box **out,
                         bool *failed)
{
    *out = NULL;
    *failed = false;
    uint32_t triangles = end > first ? (end - first) / 3 : 0;
    uint32_t run = SB_CASTER_RUN;
    if (triangles > (uint32_t)SB_CASTER_RUN * SB_CASTER_MAX_BOXES)
        run = (triangles + SB_CASTER_MAX_BOXES - 1) / SB_CASTER_MAX_BOXES;
    unsigned count = (triangles + run - 1) / run;
    if (!count)
        return 0;
    struct sb_caster_box *boxes = malloc(count * sizeof(*boxes));
    if (!boxes) {
        *failed = true;
        return 0;
    }
    for (unsigned b = 0; b < count; b++) {
        uint32_t v0 = first + 3 * run * b, v1 = v0 + 3 * run;
        if (v1 > first + 3 * triangles)
            v1 = first + 3 * triangles;
        for (int k = 0; k < 3; k++) {
            boxes[b].min[k] = HUGE_VAL;
            boxes[b].max[k] = -HUGE_VAL;
        }
        for (uint32_t v = v0; v < v1; v++)
            for (int k = 0; k < 3; k++) {
                boxes[b].min[k] = fmin(boxes[b].min[k], vertices[v].position[k]);
                boxes[b].max[k] = fmax(boxes[b].max[k], vertices[v].position[k]);
            }
    }
    *out = boxes;
    return count;
}

void sb_cascade_caster_rect(const struct sb_mat4 *view_proj, const double camera_m[3],
                            const struct sb_caster_box *boxes, unsigned count, unsigned map_size, int32_t rect[4])
{
    /* In texel units, x = (ndc + 1) size / 2; a texel i is drawn when its
     * centre i + 0.5 is covered, so [floor(lo), ceil(hi)) holds them all,
     * and one more texel each side absorbs the fp32 rounding of the GPU's
     * transform. */
    double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
    for (unsigned b = 0; b < count; b++)
        for (int corner = 0; corner < 8; corner++) {
            double p[3], ndc[3];
            for (int k = 0; k < 3; k++)
                p[k] = ((corner >> k) & 1 ? boxes[b].max[k] : boxes[b].min[k]) - camera_m[k];
            sb_mat4_project(view_proj, p, ndc);
            for (int k = 0; k < 2; k++) {
                double x = (ndc[k] + 1.0) * 0.5 * map_size;
                lo[k] = fmin(lo[k], x);
                hi[k] = fmax(hi[k], x);
            }
        }
    for (int k = 0; k < 2; k++) {
        double a = fmax(floor(lo[k]) - 1.0, 0.0), b = fmin(ceil(hi[k]) + 1.0, (double)map_size);
        rect[k] = (int32_t)(a < b ? a : 0.0);
        rect[k + 2] = (int32_t)(a < b ? b : 0.0);
    }
    if (rect[0] >= rect[2] || rect[1] >= rect[3])
        rect[0] = rect[1] = rect[2] = rect[3] = 0;
}

bool sb_far_shadow_compute(const double camera_m[3], const double light[3], const struct sb_caster_box *boxes,
                           unsigned count, const double world_min[3], const double world_max[3], unsigned map_size,
                           struct sb_mat4 *view_proj, double *texel_m, double *depth_m)
{
    if (!count || !map_size)
        return false;
    /* the light's frame: e1 level (or along x under a light overhead), e2 = l x e1 */
    double e1[3] = {-light[2], 0.0, light[0]}, len = sqrt(e1[0] * e1[0] + e1[2] * e1[2]);
    if (len < 1e-6) {
        e1[0] = 1.0;
        e1[2] = 0.0;
    } else {
        e1[0] /= len;
        e1[2] /= len;
    }
    double e2[3] = {light[1] * e1[2] - light[2] * e1[1], light[2] * e1[0] - light[0] * e1[2],
                    light[0] * e1[1] - light[1] * e1[0]};
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    const double *axes[3] = {e1, e2, light};
    for (unsigned b = 0; b <= count; b++) { /* the casters' boxes across; the world's too along the light */
        const double *mn = b < count ? boxes[b].min : world_min, *mx = b < count ? boxes[b].max : world_max;
        for (int corner = 0; corner < 8; corner++) {
            double p[3] = {(corner & 1 ? mx : mn)[0], (corner & 2 ? mx : mn)[1], (corner & 4 ? mx : mn)[2]};
            for (int a = b < count ? 0 : 2; a < 3; a++) {
                double d = p[0] * axes[a][0] + p[1] * axes[a][1] + p[2] * axes[a][2];
                lo[a] = fmin(lo[a], d);
                hi[a] = fmax(hi[a], d);
            }
        }
    }
    /* square texels, two to spare each side */
    double span = fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), 1e-3);
    double texel = span / (map_size - 4.0);
    for (int a = 0; a < 2; a++) {
        double mid = 0.5 * (lo[a] + hi[a]);
        lo[a] = mid - 0.5 * map_size * texel;
        hi[a] = mid + 0.5 * map_size * texel;
    }
    double depth = fmax(hi[2] - lo[2], 1e-3) + 2.0; /* a metre past each end */
    hi[2] += 1.0;
    memset(view_proj, 0, sizeof(*view_proj));
    for (int a = 0; a < 2; a++) { /* clip = 2 (x.e - lo) / span - 1, x = offset + camera */
        double scale = 2.0 / (hi[a] - lo[a]);
        double at = camera_m[0] * axes[a][0] + camera_m[1] * axes[a][1] + camera_m[2] * axes[a][2];
        for (int k = 0; k < 3; k++)
            view_proj->m[4 * k + a] = scale * axes[a][k];
        view_proj->m[12 + a] = scale * (at - lo[a]) - 1.0;
    }
    double at = camera_m[0] * light[0] + camera_m[1] * light[1] + camera_m[2] * light[2];
    for (int k = 0; k < 3; k++) /* depth 0 nearest the light */
        view_proj->m[4 * k + 2] = -light[k] / depth;
    view_proj->m[14] = (hi[2] - at) / depth;
    view_proj->m[15] = 1.0;
    *texel_m = texel;
    *depth_m = depth;
    return true;
}
