#include "world.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "level.h"
#include "load.h"
#include "log.h"
#include "world_file.h"

/* Copy the mesh's textures after the world's. */
static enum sb_result append_textures(struct sb_world *w, const struct sb_mesh *mesh)
{
    for (uint32_t k = 0; k < mesh->texture_count; k++, w->texture_count++) {
        struct sb_mesh_texture *t = &w->textures[w->texture_count];
        *t = mesh->texture_list[k];
        t->rgba = malloc(sb_texture_bytes(t));
        if (!t->rgba)
            return SB_ERR_NOMEM;
        memcpy(t->rgba, mesh->texture_list[k].rgba, sb_texture_bytes(t));
    }
    return SB_OK;
}

/* A record after the world's for each of the mesh's materials that emits
 * light: emission[material] its index + 1, 0 for those that do not. */
static enum sb_result append_emissive(struct sb_world *w, const struct sb_mesh *mesh, uint32_t texture_base,
                                      uint32_t *emission)
{
    for (uint32_t k = 0; k < mesh->material_count; k++) {
        const struct sb_mesh_material *m = &mesh->material_list[k];
        emission[k] = 0;
        if (!(m->emissive[0] > 0 || m->emissive[1] > 0 || m->emissive[2] > 0))
            continue;
        struct sb_emissive_gpu *grown = realloc(w->emissive, (w->emissive_count + 1) * sizeof(*grown));
        if (!grown)
            return SB_ERR_NOMEM;
        w->emissive = grown;
        struct sb_emissive_gpu *e = &w->emissive[w->emissive_count++];
        memcpy(e->radiance, m->emissive, sizeof(m->emissive));
        int32_t texture = mesh->uvs ? m->textures[SB_TEXTURE_EMISSIVE] : -1;
        e->radiance[3] = texture >= 0 ? (float)(texture + (int32_t)texture_base + 1) : 0.0f;
        emission[k] = w->emissive_count;
    }
    return SB_OK;
}

/* Append the mesh's triangles as vertices, in two passes: those that cast
 * no shadow, then the casters (from *caster_first), each in the mesh's
 * order; its texture indices from texture_base, its emitting materials'
 * records from emission[] (append_emissive). */
static void append_mesh(struct sb_world *w, const struct sb_mesh *mesh, uint32_t texture_base,
                        const uint32_t *emission, uint32_t *caster_first)
{
    for (int casters = 0; casters <= 1; casters++) {
        if (casters)
            *caster_first = w->vertex_count;
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
            int32_t base = mesh->uvs && m->textures[SB_TEXTURE_BASE_COLOR] >= 0
                               ? m->textures[SB_TEXTURE_BASE_COLOR] + (int32_t)texture_base
                               : -1;
            int32_t mr = mesh->uvs && m->textures[SB_TEXTURE_METALLIC_ROUGHNESS] >= 0
                             ? m->textures[SB_TEXTURE_METALLIC_ROUGHNESS] + (int32_t)texture_base
                             : -1;
            int32_t normal = mesh->uvs && mesh->tangents && m->textures[SB_TEXTURE_NORMAL] >= 0
                                 ? m->textures[SB_TEXTURE_NORMAL] + (int32_t)texture_base
                                 : -1;
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
                v->albedo[3] = (float)emission[mesh->materials[t]];
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
}

static enum sb_result from(enum sb_result res, struct sb_mesh *mesh, struct sb_world *w);

enum sb_result sb_world_from_mesh(const struct sb_mesh *mesh, struct sb_world *w)
{
    memset(w, 0, sizeof(*w));
    if ((uint64_t)mesh->triangle_count * 3 > UINT32_MAX)
        return SB_ERR_TOO_LARGE;
    w->vertices = calloc((size_t)mesh->triangle_count * 3 + 1, sizeof(*w->vertices));
    w->textures = calloc(mesh->texture_count + 1, sizeof(*w->textures));
    enum sb_result res = w->vertices && w->textures ? append_textures(w, mesh) : SB_ERR_NOMEM;
    if (res) {
        sb_world_finish(w);
        return res;
    }
    uint32_t *emission = malloc((mesh->material_count + 1) * sizeof(*emission));
    res = emission ? append_emissive(w, mesh, 0, emission) : SB_ERR_NOMEM;
    if (!res)
        append_mesh(w, mesh, 0, emission, &w->caster_first_vertex);
    free(emission);
    if (res) {
        sb_world_finish(w);
        return res;
    }
    sb_mesh_hash(mesh, w->mesh_hash);
    return SB_OK;
}

void sb_world_place(const struct sb_world *w, uint32_t instance, const float p[3], double out[3])
{
    const struct sb_instance_gpu *in = &w->instances[instance];
    for (int r = 0; r < 3; r++)
        out[r] = (double)in->to_world[r][0] * p[0] + (double)in->to_world[r][1] * p[1] +
                 (double)in->to_world[r][2] * p[2] + in->to_world[r][3];
}

/* The level's meshes once, each in its own space, and its instances,
 * sorted by mesh (a draw a mesh), each with its normals' matrix. */
static enum sb_result from_instanced_level(const struct sb_level *level, struct sb_world *w)
{
    uint64_t vertices = 0;
    uint32_t textures = 0;
    for (uint32_t m = 0; m < level->mesh_count; m++) {
        vertices += 3ull * level->meshes[m].triangle_count;
        textures += level->meshes[m].texture_count;
    }
    if (vertices > UINT32_MAX) {
        sb_error("the world's meshes hold %llu vertices: at most 2^32", (unsigned long long)vertices);
        return SB_ERR_TOO_LARGE;
    }
    w->vertices = calloc(vertices + 1, sizeof(*w->vertices));
    w->textures = calloc(textures + 1, sizeof(*w->textures));
    w->meshes = calloc(level->mesh_count, sizeof(*w->meshes));
    w->instances = calloc(level->instance_count, sizeof(*w->instances));
    w->instance_mesh = calloc(level->instance_count, sizeof(*w->instance_mesh));
    uint32_t *first = calloc(level->mesh_count + 1, sizeof(*first));
    enum sb_result res = w->vertices && w->textures && w->meshes && w->instances && w->instance_mesh && first
                             ? SB_OK
                             : SB_ERR_NOMEM;
    for (uint32_t m = 0; m < level->mesh_count && !res; m++) {
        struct sb_world_mesh_range *range = &w->meshes[w->mesh_count++];
        uint32_t texture_base = w->texture_count;
        if ((res = append_textures(w, &level->meshes[m])))
            break;
        uint32_t *emission = malloc((level->meshes[m].material_count + 1) * sizeof(*emission));
        res = emission ? append_emissive(w, &level->meshes[m], texture_base, emission) : SB_ERR_NOMEM;
        if (res) {
            free(emission);
            break;
        }
        range->first_vertex = w->vertex_count;
        append_mesh(w, &level->meshes[m], texture_base, emission, &range->caster_first_vertex);
        free(emission);
        range->end_vertex = w->vertex_count;
        for (int i = 0; i < 3; i++) {
            range->caster_min[i] = range->min[i] = INFINITY;
            range->caster_max[i] = range->max[i] = -INFINITY;
        }
        for (uint32_t v = range->first_vertex; v < range->end_vertex; v++)
            for (int i = 0; i < 3; i++) {
                float x = w->vertices[v].position[i];
                range->min[i] = fminf(range->min[i], x);
                range->max[i] = fmaxf(range->max[i], x);
                if (v >= range->caster_first_vertex) {
                    range->caster_min[i] = fminf(range->caster_min[i], x);
                    range->caster_max[i] = fmaxf(range->caster_max[i], x);
                }
            }
    }
    /* a counting sort by mesh: each mesh's instances in the level's order */
    for (uint32_t i = 0; i < level->instance_count && !res; i++)
        first[level->instances[i].mesh + 1]++;
    for (uint32_t m = 0; m < level->mesh_count && !res; m++)
        first[m + 1] += first[m];
    for (uint32_t i = 0; i < level->instance_count && !res; i++) {
        const struct sb_bvh_instance *in = &level->instances[i];
        uint32_t at = first[in->mesh]++;
        struct sb_instance_gpu *out = &w->instances[at];
        const double(*a)[4] = in->to_world;
        /* the normals': the inverse transpose of the linear part, its cofactors over the determinant */
        double c[3][3];
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++)
                c[r][k] = a[(r + 1) % 3][(k + 1) % 3] * a[(r + 2) % 3][(k + 2) % 3] -
                          a[(r + 1) % 3][(k + 2) % 3] * a[(r + 2) % 3][(k + 1) % 3];
        double det = a[0][0] * c[0][0] + a[0][1] * c[0][1] + a[0][2] * c[0][2];
        for (int r = 0; r < 3; r++) {
            for (int k = 0; k < 4; k++)
                out->to_world[r][k] = (float)a[r][k];
            for (int k = 0; k < 3; k++)
                out->normal[r][k] = (float)(c[r][k] / det);
        }
        w->instance_mesh[at] = in->mesh;
    }
    w->instance_count = res ? 0 : level->instance_count;
    free(first);
    return res;
}

enum sb_result sb_world_from_level(const struct sb_level *level, struct sb_world *w)
{
    memset(w, 0, sizeof(*w));
    enum sb_result res;
    if (level->instance_count) {
        res = from_instanced_level(level, w);
        if (res)
            sb_world_finish(w);
    } else {
        struct sb_mesh mesh = {0};
        res = from(sb_level_flatten(level, &mesh), &mesh, w);
    }
    if (!res)
        sb_level_hash(level, w->mesh_hash);
    return res;
}

static double dot3d(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Where the upward triangle (a, b, c) lies over (x, z): its height there
 * into *y, false when it does not. */
static bool height_over(const double a[3], const double b[3], const double c[3], double x, double z, double *y)
{
    /* barycentrics of (x, z) in the triangle's projection */
    double d = (b[2] - c[2]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[2] - c[2]);
    if (d == 0.0)
        return false;
    double l1 = ((b[2] - c[2]) * (x - c[0]) + (c[0] - b[0]) * (z - c[2])) / d;
    double l2 = ((c[2] - a[2]) * (x - c[0]) + (a[0] - c[0]) * (z - c[2])) / d;
    double l3 = 1.0 - l1 - l2;
    if (l1 < 0 || l2 < 0 || l3 < 0)
        return false;
    *y = l1 * a[1] + l2 * b[1] + l3 * c[1];
    return true;
}

void sb_world_caster_bounds(const struct sb_world *w, double lo[3], double hi[3])
{
    if (!w->instance_count) {
        for (uint32_t v = w->caster_first_vertex; v < w->vertex_count; v++)
            for (int i = 0; i < 3; i++) {
                lo[i] = fmin(lo[i], w->vertices[v].position[i]);
                hi[i] = fmax(hi[i], w->vertices[v].position[i]);
            }
        return;
    }
    for (uint32_t i = 0; i < w->instance_count; i++) {
        double box[2][3];
        if (sb_world_instance_box(w, i, true, box))
            for (int k = 0; k < 3; k++) {
                lo[k] = fmin(lo[k], box[0][k]);
                hi[k] = fmax(hi[k], box[1][k]);
            }
    }
}

bool sb_world_instance_box(const struct sb_world *w, uint32_t i, bool casters, double box[2][3])
{
    const struct sb_world_mesh_range *range = &w->meshes[w->instance_mesh[i]];
    const float *lo = casters ? range->caster_min : range->min, *hi = casters ? range->caster_max : range->max;
    if (!(lo[0] <= hi[0]))
        return false;
    for (int k = 0; k < 3; k++) {
        box[0][k] = INFINITY;
        box[1][k] = -INFINITY;
    }
    for (int corner = 0; corner < 8; corner++) {
        float p[3];
        double q[3];
        for (int k = 0; k < 3; k++)
            p[k] = (corner >> k) & 1 ? hi[k] : lo[k];
        sb_world_place(w, i, p, q);
        for (int k = 0; k < 3; k++) {
            box[0][k] = fmin(box[0][k], q[k]);
            box[1][k] = fmax(box[1][k], q[k]);
        }
    }
    return true;
}

bool sb_world_lift(const struct sb_world *w, double eye_m, double camera_m[3], double *surface_m)
{
    bool below = false, above = false;
    double highest = -INFINITY, x = camera_m[0], z = camera_m[2];
    uint32_t copies = w->instance_count ? w->instance_count : 1;
    for (uint32_t i = 0; i < copies; i++) {
        const struct sb_world_mesh_range *range = w->instance_count ? &w->meshes[w->instance_mesh[i]] : NULL;
        uint32_t first = range ? range->first_vertex : 0, end = range ? range->end_vertex : w->vertex_count;
        for (uint32_t v = first; v + 2 < end; v += 3) {
            const struct sb_vertex_gpu *t = &w->vertices[v];
            double p[3][3];
            float up = t->normal[1];
            if (range) { /* upward in the world: the normal's matrix's second row */
                const float *n = w->instances[i].normal[1];
                up = n[0] * t->normal[0] + n[1] * t->normal[1] + n[2] * t->normal[2];
            }
            if (!(up > 0.0f))
                continue; /* upward faces only */
            for (int k = 0; k < 3; k++) {
                if (range)
                    sb_world_place(w, i, t[k].position, p[k]);
                else
                    for (int c = 0; c < 3; c++)
                        p[k][c] = t[k].position[c];
            }
            double y;
            if (!height_over(p[0], p[1], p[2], x, z, &y))
                continue;
            below = below || y <= camera_m[1];
            above = above || y > camera_m[1];
            highest = fmax(highest, y);
        }
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
    sb_world_caster_bounds(w, lo, hi);
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
    free(w->meshes);
    free(w->instances);
    free(w->instance_mesh);
    for (uint32_t k = 0; k < w->texture_count; k++)
        free(w->textures[k].rgba);
    free(w->textures);
    free(w->emissive);
    free(w->vertices);
    memset(w, 0, sizeof(*w));
}

enum sb_result sb_world_mesh(const struct sb_world *world, bool casters_only, struct sb_mesh *mesh)
{
    memset(mesh, 0, sizeof(*mesh));
    /* the triangles placed: (copy, first vertex, end) runs */
    uint32_t copies = world->instance_count ? world->instance_count : 1;
    uint64_t n = 0;
    for (uint32_t i = 0; i < copies; i++) {
        const struct sb_world_mesh_range *r = world->instance_count ? &world->meshes[world->instance_mesh[i]] : NULL;
        uint32_t first = r ? (casters_only ? r->caster_first_vertex : r->first_vertex)
                           : (casters_only ? world->caster_first_vertex : 0);
        n += ((r ? r->end_vertex : world->vertex_count) - first) / 3;
    }
    if (n > SB_MESH_MAX_TRIANGLES) {
        sb_error("the world places %llu triangles: as one mesh, at most %u", (unsigned long long)n,
                 SB_MESH_MAX_TRIANGLES);
        return SB_ERR_TOO_LARGE;
    }
    mesh->positions = malloc((size_t)n * 9 * sizeof(float) + 1);
    mesh->indices = malloc((size_t)n * 3 * sizeof(uint32_t) + 1);
    mesh->materials = malloc((size_t)n * sizeof(uint32_t) + 1);
    mesh->material_list = calloc(2, sizeof(*mesh->material_list));
    if (!mesh->positions || !mesh->indices || !mesh->materials || !mesh->material_list) {
        sb_mesh_finish(mesh);
        return SB_ERR_NOMEM;
    }
    uint32_t out = 0;
    for (uint32_t i = 0; i < copies; i++) {
        const struct sb_world_mesh_range *r = world->instance_count ? &world->meshes[world->instance_mesh[i]] : NULL;
        uint32_t casters = r ? r->caster_first_vertex : world->caster_first_vertex;
        uint32_t first = casters_only ? casters : r ? r->first_vertex : 0;
        uint32_t end = r ? r->end_vertex : world->vertex_count;
        for (uint32_t v = first; v < end; v++, out++) {
            float *p = &mesh->positions[3 * (size_t)out];
            if (r) {
                double q[3];
                sb_world_place(world, i, world->vertices[v].position, q);
                for (int k = 0; k < 3; k++)
                    p[k] = (float)q[k];
            } else {
                memcpy(p, world->vertices[v].position, 3 * sizeof(float));
            }
            mesh->indices[out] = out;
            if (out % 3 == 0)
                mesh->materials[out / 3] = v >= casters;
        }
    }
    mesh->material_list[1].casts_shadows = true;
    mesh->vertex_count = 3 * (uint32_t)n;
    mesh->triangle_count = (uint32_t)n;
    mesh->material_count = 2;
    return SB_OK;
}
