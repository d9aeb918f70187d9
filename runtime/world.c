#include "world.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "level.h"
#include "load.h"
#include "world_file.h"

enum sb_result sb_world_from_mesh(const struct sb_mesh *mesh, struct sb_world *w)
{
    memset(w, 0, sizeof(*w));
    if ((uint64_t)mesh->triangle_count * 3 > UINT32_MAX)
        return SB_ERR_TOO_LARGE;
    w->vertices = calloc((size_t)mesh->triangle_count * 3 + 1, sizeof(*w->vertices));
    w->textures = calloc(mesh->texture_count + 1, sizeof(*w->textures));
    if (!w->vertices || !w->textures) {
        sb_world_finish(w);
        return SB_ERR_NOMEM;
    }
    for (uint32_t k = 0; k < mesh->texture_count; k++, w->texture_count++) {
        w->textures[k] = mesh->texture_list[k];
        w->textures[k].rgba = malloc(sb_texture_bytes(&w->textures[k]));
        if (!w->textures[k].rgba) {
            sb_world_finish(w);
            return SB_ERR_NOMEM;
        }
        memcpy(w->textures[k].rgba, mesh->texture_list[k].rgba, sb_texture_bytes(&w->textures[k]));
    }
    /* two passes: the triangles that cast no shadow, then the casters, each in the mesh's order */
    for (int casters = 0; casters <= 1; casters++) {
        if (casters)
            w->caster_first_vertex = w->vertex_count;
        for (uint32_t t = 0; t < mesh->triangle_count; t++) {
            const struct sb_mesh_material *m = &mesh->material_list[mesh->materials[t]];
            if (m->casts_shadows != (casters == 1))
                continue;
            const float *p[3];
            for (int k = 0; k < 3; k++)
                p[k] = &mesh->positions[3 * (size_t)mesh->indices[3 * (size_t)t + k]];
            double e1[3], e2[3];
            for (int i = 0; i < 3; i++) {
                e1[i] = (double)p[1][i] - p[0][i];
                e2[i] = (double)p[2][i] - p[0][i];
            }
            double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
            double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            /* a texture the vertices name where they have coordinates */
            int32_t base = mesh->uvs ? m->textures[SB_TEXTURE_BASE_COLOR] : -1;
            int32_t mr = mesh->uvs ? m->textures[SB_TEXTURE_METALLIC_ROUGHNESS] : -1;
            int32_t normal = mesh->uvs && mesh->tangents ? m->textures[SB_TEXTURE_NORMAL] : -1;
            for (int k = 0; k < 3; k++) {
                struct sb_vertex_gpu *v = &w->vertices[w->vertex_count++];
                uint32_t vertex = mesh->indices[3 * (size_t)t + k];
                for (int i = 0; i < 3; i++) {
                    v->position[i] = p[k][i];
                    v->normal[i] = len > 0 ? (float)(n[i] / len) : (i == 1);
                    v->albedo[i] = m->albedo[i];
                }
                v->position[3] = m->metallic;
                v->normal[3] = m->roughness;
                v->albedo[3] = 1.0f;
                if (mesh->uvs) {
                    v->uv[0] = mesh->uvs[2 * (size_t)vertex];
                    v->uv[1] = mesh->uvs[2 * (size_t)vertex + 1];
                }
                v->uv[2] = (float)(base + 1);
                v->uv[3] = (float)(mr + 1);
                if (normal >= 0) {
                    const float *tangent = &mesh->tangents[4 * (size_t)vertex];
                    memcpy(v->tangent, tangent, 3 * sizeof(float));
                    v->tangent[3] = (float)(normal + 1) * (tangent[3] < 0 ? -1.0f : 1.0f);
                }
            }
        }
    }
    sb_mesh_hash(mesh, w->mesh_hash);
    return SB_OK;
}

static double dot3d(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

bool sb_world_lift(const struct sb_world *w, double eye_m, double camera_m[3], double *surface_m)
{
    bool below = false, above = false;
    double highest = -INFINITY, x = camera_m[0], z = camera_m[2];
    for (uint32_t v = 0; v + 2 < w->vertex_count; v += 3) {
        const float *a = w->vertices[v].position, *b = w->vertices[v + 1].position, *c = w->vertices[v + 2].position;
        if (!(w->vertices[v].normal[1] > 0.0f))
            continue; /* upward faces only */
        /* barycentrics of (x, z) in the triangle's projection */
        double d = ((double)b[2] - c[2]) * ((double)a[0] - c[0]) + ((double)c[0] - b[0]) * ((double)a[2] - c[2]);
        if (d == 0.0)
            continue;
        double l1 = (((double)b[2] - c[2]) * (x - c[0]) + ((double)c[0] - b[0]) * (z - c[2])) / d;
        double l2 = (((double)c[2] - a[2]) * (x - c[0]) + ((double)a[0] - c[0]) * (z - c[2])) / d;
        double l3 = 1.0 - l1 - l2;
        if (l1 < 0 || l2 < 0 || l3 < 0)
            continue;
        double y = l1 * a[1] + l2 * b[1] + l3 * c[1];
        below = below || y <= camera_m[1];
        above = above || y > camera_m[1];
        highest = fmax(highest, y);
    }
    if (below || !above)
        return false;
    *surface_m = highest;
    camera_m[1] = round((highest + eye_m) * 1e4) / 1e4;
    return true;
}

/* Look north and 20 degrees down at the box's centre from where its
 * bounding sphere fills the narrower field of view. */
static bool frame_box(const double lo[3], const double hi[3], double aspect, double fov_y, double camera_m[3],
                      double *yaw, double *pitch)
{
    double tan_v = tan(0.5 * fov_y), tan_h = tan_v * aspect;
    double centre[3], radius = 0.0;
    for (int i = 0; i < 3; i++) {
        centre[i] = 0.5 * (lo[i] + hi[i]);
        radius += 0.25 * (hi[i] - lo[i]) * (hi[i] - lo[i]);
    }
    radius = sqrt(radius);
    double half = fmin(atan(tan_v), atan(tan_h)), distance = 1.05 * radius / sin(half);
    double down = 20.0 * M_PI / 180.0;
    /* to 0.1 mm, so that the position skyview reports reads plainly */
    camera_m[0] = round(centre[0] * 1e4) / 1e4;
    camera_m[1] = round(fmax(centre[1] + distance * sin(down), 0.1) * 1e4) / 1e4;
    camera_m[2] = round((centre[2] + distance * cos(down)) * 1e4) / 1e4;
    *yaw = 0.0;
    *pitch = atan2(centre[1] - camera_m[1], camera_m[2] - centre[2]);
    return true;
}

bool sb_world_frame(const struct sb_world *w, double aspect, double fov_y, double camera_m[3], double *yaw,
                    double *pitch)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = w->caster_first_vertex; v < w->vertex_count; v++)
        for (int i = 0; i < 3; i++) {
            lo[i] = fmin(lo[i], w->vertices[v].position[i]);
            hi[i] = fmax(hi[i], w->vertices[v].position[i]);
        }
    if (!(lo[0] <= hi[0]))
        return false;
    bool inside = true;
    for (int i = 0; i < 3; i++)
        inside = inside && camera_m[i] >= lo[i] && camera_m[i] <= hi[i];
    /* inside a level's box, the camera stands in it; inside a model's, in
     * the model (a truck's cab, a house's walls), which it does not show */
    if (inside && fmax(hi[0] - lo[0], hi[2] - lo[2]) > SB_WORLD_MODEL_M)
        return false;
    if (inside)
        return frame_box(lo, hi, aspect, fov_y, camera_m, yaw, pitch);
    /* The frustum's four sides through the camera, normals inward; the box
     * is out of view when all its corners lie behind one of them, or behind
     * the camera. */
    double tan_v = tan(0.5 * fov_y), tan_h = tan_v * aspect;
    double f[3] = {sin(*yaw) * cos(*pitch), sin(*pitch), -cos(*yaw) * cos(*pitch)};
    double r[3] = {cos(*yaw), 0.0, sin(*yaw)};
    double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    double planes[5][3];
    for (int i = 0; i < 3; i++) {
        planes[0][i] = f[i] * tan_v - u[i];
        planes[1][i] = f[i] * tan_v + u[i];
        planes[2][i] = f[i] * tan_h - r[i];
        planes[3][i] = f[i] * tan_h + r[i];
        planes[4][i] = f[i];
    }
    bool seen = true;
    for (int k = 0; k < 5 && seen; k++) {
        bool all_behind = true;
        for (int c = 0; c < 8 && all_behind; c++) {
            double d[3];
            for (int i = 0; i < 3; i++)
                d[i] = ((c >> i) & 1 ? hi[i] : lo[i]) - camera_m[i];
            all_behind = dot3d(planes[k], d) < 0.0;
        }
        seen = !all_behind;
    }
    if (seen)
        return false;
    return frame_box(lo, hi, aspect, fov_y, camera_m, yaw, pitch);
}

static enum sb_result from(enum sb_result res, struct sb_mesh *mesh, struct sb_world *w)
{
    if (!res)
        res = sb_world_from_mesh(mesh, w);
    if (res)
        sb_world_finish(w);
    sb_mesh_finish(mesh);
    return res;
}

enum sb_result sb_world_from_level(const struct sb_level *level, struct sb_world *w)
{
    memset(w, 0, sizeof(*w));
    struct sb_mesh mesh = {0};
    enum sb_result res = from(sb_level_flatten(level, &mesh), &mesh, w);
    if (!res)
        sb_level_hash(level, w->mesh_hash);
    return res;
}

enum sb_result sb_world_load(const char *path, const struct sb_mesh_load_params *params, struct sb_world *w)
{
    memset(w, 0, sizeof(*w));
    struct sb_mesh mesh = {0};
    return from(sb_mesh_load(path, params, &mesh), &mesh, w);
}

enum sb_result sb_world_parse(const char *json, size_t size, const char *source, struct sb_world *w)
{
    memset(w, 0, sizeof(*w));
    struct sb_mesh mesh = {0};
    return from(sb_world_file_parse(json, size, source, NULL, &mesh, NULL), &mesh, w);
}

void sb_world_finish(struct sb_world *w)
{
    for (uint32_t k = 0; k < w->texture_count; k++)
        free(w->textures[k].rgba);
    free(w->textures);
    free(w->vertices);
    memset(w, 0, sizeof(*w));
}

enum sb_result sb_world_mesh(const struct sb_world *world, bool casters_only, struct sb_mesh *mesh)
{
    memset(mesh, 0, sizeof(*mesh));
    uint32_t first = casters_only ? world->caster_first_vertex : 0;
    uint32_t n = (world->vertex_count - first) / 3;
    mesh->positions = malloc((size_t)n * 9 * sizeof(float) + 1);
    mesh->indices = malloc((size_t)n * 3 * sizeof(uint32_t) + 1);
    mesh->materials = malloc((size_t)n * sizeof(uint32_t) + 1);
    mesh->material_list = calloc(2, sizeof(*mesh->material_list));
    if (!mesh->positions || !mesh->indices || !mesh->materials || !mesh->material_list) {
        sb_mesh_finish(mesh);
        return SB_ERR_NOMEM;
    }
    for (uint32_t v = 0; v < 3 * n; v++) {
        memcpy(&mesh->positions[3 * (size_t)v], world->vertices[first + v].position, 3 * sizeof(float));
        mesh->indices[v] = v;
    }
    for (uint32_t t = 0; t < n; t++)
        mesh->materials[t] = first + 3 * t >= world->caster_first_vertex;
    mesh->material_list[1].casts_shadows = true;
    mesh->vertex_count = 3 * n;
    mesh->triangle_count = n;
    mesh->material_count = 2;
    return SB_OK;
}
