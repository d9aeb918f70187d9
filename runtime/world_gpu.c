/*
 * The world on the device (renderer_internal.h): its vertices, textures,
 * emitting materials, instances and their draws, its BVH when the scene is
 * traced, the boxes that bound it and its casters, and each frame's cull
 * of an instanced world's raster draws.
 */
#include "renderer_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "log.h"
#include "world.h"

/* The world's box, and its casters' boxes for the cascades (shadows.h). */
static enum sb_result world_bounds(struct sb_renderer *r, const struct sb_world *world)
{
    r->vertex_count = world->vertex_count;
    r->caster_first_vertex = world->caster_first_vertex;
    for (int i = 0; i < 3; i++) {
        r->world_min_m[i] = world->vertex_count ? INFINITY : 0.0;
        r->world_max_m[i] = world->vertex_count ? -INFINITY : 0.0;
    }
    bool failed = false;
    if (world->instance_count) {
        /* every instance's box, which also bounds its casters for the cascades */
        r->caster_boxes = calloc(world->instance_count, sizeof(*r->caster_boxes));
        failed = !r->caster_boxes;
        for (uint32_t i = 0; i < world->instance_count && !failed; i++) {
            double box[2][3];
            if (sb_world_instance_box(world, i, false, box))
                for (int k = 0; k < 3; k++) {
                    r->world_min_m[k] = fmin(r->world_min_m[k], box[0][k]);
                    r->world_max_m[k] = fmax(r->world_max_m[k], box[1][k]);
                }
            if (sb_world_instance_box(world, i, true, box)) {
                struct sb_caster_box *c = &r->caster_boxes[r->caster_box_count++];
                memcpy(c->min, box[0], sizeof(c->min));
                memcpy(c->max, box[1], sizeof(c->max));
            }
        }
    } else {
        for (uint32_t v = 0; v < world->vertex_count; v++)
            for (int i = 0; i < 3; i++) {
                r->world_min_m[i] = fmin(r->world_min_m[i], world->vertices[v].position[i]);
                r->world_max_m[i] = fmax(r->world_max_m[i], world->vertices[v].position[i]);
            }
        r->caster_box_count = sb_caster_boxes(world->vertices, world->caster_first_vertex, world->vertex_count,
                                              &r->caster_boxes, &failed);
    }
    return failed ? SB_ERR_NOMEM : SB_OK;
}

/* The world's textures, their mips made on the device (vulkan/texels.h). */
static enum sb_result upload_textures(struct sb_renderer *r, const struct sb_world *world)
{
    if (r->params.no_textures) { /* none, and no vertex names one */
        struct sb_vertex_gpu *v = r->vertices.mapped;
        for (uint32_t i = 0; i < world->vertex_count; i++) {
            v[i].uv[2] = v[i].uv[3] = 0.0f;
            v[i].tangent[3] = 0.0f;
        }
        return sb_texel_set_create(r->vk, NULL, 0, &r->textures);
    }
    struct sb_texel_image *images = calloc(world->texture_count + 1, sizeof(*images));
    if (!images)
        return SB_ERR_NOMEM;
    for (uint32_t k = 0; k < world->texture_count; k++) {
        const struct sb_mesh_texture *t = &world->textures[k];
        images[k] = (struct sb_texel_image){.width = t->width,
                                            .height = t->height,
                                            .wrap = {t->wrap[0], t->wrap[1]},
                                            .srgb = t->srgb != 0,
                                            .rgba = t->rgba};
    }
    enum sb_result res = sb_texel_set_create(r->vk, images, world->texture_count, &r->textures);
    free(images);
    if (!res && world->texture_count)
        sb_info("world: %u textures, %.1f MiB with their mips (%.2f ms on the device)", world->texture_count,
                r->textures.texel_count * 4.0 / (1 << 20), r->textures.gpu_ms);
    return res;
}

/* The world's emitting materials (one zero record when none); with
 * --no-textures, without their textures. */
static enum sb_result upload_emissive(struct sb_renderer *r, const struct sb_world *world)
{
    uint32_t n = world->emissive_count ? world->emissive_count : 1;
    enum sb_result res =
        sb_renderer_upload(r, world->emissive, n * sizeof(struct sb_emissive_gpu), "emissive", &r->emissive);
    struct sb_emissive_gpu *e = r->emissive.mapped;
    if (!res && !world->emissive_count)
        memset(e, 0, sizeof(*e));
    r->emissive_count = world->emissive_count;
    for (uint32_t i = 0; !res && r->params.no_textures && i < world->emissive_count; i++)
        e[i].radiance[3] = 0.0f;
    return res;
}

/* An instanced world's BVH: one a mesh (its vertices in its own space),
 * a top level over its instances, in the world's order (the traced
 * kernels read an instance's sb_instance_gpu by the index its record holds). */
static enum sb_result build_instanced_bvh(const struct sb_world *world, struct sb_bvh *bvh)
{
    struct sb_mesh *meshes = calloc(world->mesh_count, sizeof(*meshes));
    const struct sb_mesh **list = calloc(world->mesh_count, sizeof(*list));
    struct sb_bvh_instance *instances = calloc(world->instance_count, sizeof(*instances));
    enum sb_result res = meshes && list && instances ? SB_OK : SB_ERR_NOMEM;
    for (uint32_t m = 0; m < world->mesh_count && !res; m++) {
        const struct sb_world_mesh_range *range = &world->meshes[m];
        struct sb_mesh *mesh = &meshes[m];
        uint32_t n = (range->end_vertex - range->first_vertex) / 3;
        mesh->positions = malloc((size_t)n * 9 * sizeof(float) + 1);
        mesh->indices = malloc((size_t)n * 3 * sizeof(uint32_t) + 1);
        mesh->materials = malloc((size_t)n * sizeof(uint32_t) + 1);
        mesh->material_list = calloc(2, sizeof(*mesh->material_list));
        if (!mesh->positions || !mesh->indices || !mesh->materials || !mesh->material_list) {
            res = SB_ERR_NOMEM;
            break;
        }
        for (uint32_t v = 0; v < 3 * n; v++) {
            memcpy(&mesh->positions[3 * (size_t)v], world->vertices[range->first_vertex + v].position,
                   3 * sizeof(float));
            mesh->indices[v] = v;
        }
        for (uint32_t t = 0; t < n; t++) /* 1: casts shadows (shadows.glsl) */
            mesh->materials[t] = range->first_vertex + 3 * t >= range->caster_first_vertex;
        mesh->material_list[1].casts_shadows = true;
        mesh->vertex_count = 3 * n;
        mesh->triangle_count = n;
        mesh->material_count = 2;
        list[m] = mesh;
    }
    for (uint32_t i = 0; i < world->instance_count && !res; i++) {
        instances[i].mesh = world->instance_mesh[i];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++)
                instances[i].to_world[r][c] = world->instances[i].to_world[r][c];
    }
    if (!res)
        res = sb_bvh_build_instanced(list, world->mesh_count, instances, world->instance_count, bvh);
    for (uint32_t m = 0; meshes && m < world->mesh_count; m++)
        sb_mesh_finish(&meshes[m]);
    free(meshes);
    free(list);
    free(instances);
    return res;
}

/* The world's BVH (geometry/bvh.h), which the traced scene, the fog's shadow rays and the reflections'
 * relight walk. */
static enum sb_result upload_bvh(struct sb_renderer *r, const struct sb_world *world)
{
    struct sb_bvh bvh = {0};
    enum sb_result res;
    if (world->instance_count) {
        res = build_instanced_bvh(world, &bvh);
    } else {
        struct sb_mesh mesh;
        res = sb_world_mesh(world, false, &mesh);
        if (res)
            return res;
        res = sb_bvh_build(&mesh, &bvh);
        sb_mesh_finish(&mesh);
    }
    if (!res)
        res = sb_renderer_upload(r, bvh.nodes, bvh.node_count * sizeof(*bvh.nodes), "world BVH nodes", &r->bvh_nodes);
    if (!res)
        res = sb_renderer_upload(r, bvh.triangles, bvh.triangle_count * sizeof(*bvh.triangles), "world BVH triangles",
                                 &r->bvh_triangles);
    if (!res && bvh.instance_count)
        sb_info("the world's BVH: %u triangles placed %u times, two levels, %u nodes", bvh.triangle_count,
                bvh.instance_count, bvh.node_count);
    else if (!res)
        sb_info("the world's BVH: %u triangles, %u nodes, %u deep", bvh.triangle_count, bvh.node_count, bvh.depth);
    sb_bvh_finish(&bvh);
    return res;
}

/* An instanced world's instances and its draws, a mesh each; else one
 * zero instance (every pass's set binds the buffer). */
static enum sb_result upload_instances(struct sb_renderer *r, const struct sb_world *world)
{
    uint32_t n = world->instance_count ? world->instance_count : 1;
    enum sb_result res =
        sb_renderer_upload(r, world->instances, n * sizeof(struct sb_instance_gpu), "instances", &r->instances);
    if (!res)
        res = sb_renderer_upload(r, NULL, (size_t)(2 + SB_CASCADES) * n * sizeof(uint32_t), "visible instances",
                                 &r->visible);
    if (res || !world->instance_count)
        return res;
    r->draw_groups = calloc(world->mesh_count, sizeof(*r->draw_groups));
    r->visible_ranges = calloc((size_t)(2 + SB_CASCADES) * world->mesh_count, sizeof(*r->visible_ranges));
    r->instance_boxes = calloc(n, sizeof(*r->instance_boxes));
    r->caster_instance_boxes = calloc(n, sizeof(*r->caster_instance_boxes));
    if (!r->draw_groups || !r->visible_ranges || !r->instance_boxes || !r->caster_instance_boxes)
        return SB_ERR_NOMEM;
    for (uint32_t i = 0; i < n; i++) {
        if (!sb_world_instance_box(world, i, false, r->instance_boxes[i]))
            r->instance_boxes[i][0][0] = INFINITY; /* empty: never drawn */
        if (!sb_world_instance_box(world, i, true, r->caster_instance_boxes[i]))
            r->caster_instance_boxes[i][0][0] = INFINITY;
    }
    for (uint32_t i = 0; i < world->instance_count;) { /* sorted by mesh */
        uint32_t m = world->instance_mesh[i], end = i;
        while (end < world->instance_count && world->instance_mesh[end] == m)
            end++;
        const struct sb_world_mesh_range *range = &world->meshes[m];
        r->draw_groups[r->draw_group_count++] = (struct sb_draw_group){
            .first_vertex = range->first_vertex,
            .caster_first_vertex = range->caster_first_vertex,
            .end_vertex = range->end_vertex,
            .first_instance = i,
            .instance_count = end - i,
        };
        i = end;
    }
    return SB_OK;
}

/* Whether a world box lies wholly outside a camera-relative clip space:
 * all its corners past one side (x or y beyond +-w; with `near`, w below
 * it: behind the perspective's near plane; an orthographic cascade's depth
 * is not tested, a caster behind it still shadows). */
static bool box_outside(const struct sb_mat4 *view_proj, const double camera_m[3], const double box[2][3], double near)
{
    if (!(box[0][0] <= box[1][0]))
        return true;
    int out[5] = {0, 0, 0, 0, 0};
    for (int corner = 0; corner < 8; corner++) {
        double p[3], clip[4];
        for (int k = 0; k < 3; k++)
            p[k] = box[(corner >> k) & 1][k] - camera_m[k];
        for (int row = 0; row < 4; row++)
            clip[row] = view_proj->m[row] * p[0] + view_proj->m[4 + row] * p[1] + view_proj->m[8 + row] * p[2] +
                        view_proj->m[12 + row];
        out[0] += clip[0] < -clip[3];
        out[1] += clip[0] > clip[3];
        out[2] += clip[1] < -clip[3];
        out[3] += clip[1] > clip[3];
        out[4] += near > 0 && clip[3] < near;
    }
    for (int k = 0; k < 5; k++)
        if (out[k] == 8)
            return true;
    return false;
}

/* This frame's lists of the instances each raster draw draws: those whose
 * box the frame can see, and for each cascade and the far map (when `far`)
 * those whose casters' box falls on its map (runtime/passes/scene.c and
 * shadows.c draw them). */
void sb_world_cull(struct sb_renderer *r, const struct sb_cascades *cascades, const struct sb_mat4 *far)
{
    uint32_t *visible = r->visible.mapped, at = 0;
    for (int list = 0; list <= SB_CASCADES + 1; list++)
        for (uint32_t g = 0; g < r->draw_group_count; g++) {
            const struct sb_draw_group *d = &r->draw_groups[g];
            struct sb_visible_range *range = &r->visible_ranges[list * r->draw_group_count + g];
            range->first = at;
            for (uint32_t i = d->first_instance; i < d->first_instance + d->instance_count; i++) {
                const struct sb_mat4 *map = list <= SB_CASCADES ? &cascades->view_proj[list - 1] : far;
                bool out = list == 0 ? box_outside(&r->view_proj, r->camera_m, r->instance_boxes[i], SB_NEAR_M)
                           : !map    ? true
                                     : box_outside(map, r->camera_m, r->caster_instance_boxes[i], 0.0);
                if (!out)
                    visible[at++] = i;
            }
            range->count = at - range->first;
        }
}

enum sb_result sb_world_upload(struct sb_renderer *r, const struct sb_world *world)
{
    enum sb_result res = world_bounds(r, world);
    if (!res)
        res = sb_renderer_upload(r, world->vertices, world->vertex_count * sizeof(struct sb_vertex_gpu), "world",
                                 &r->vertices);
    if (!res)
        res = upload_textures(r, world);
    if (!res)
        res = upload_emissive(r, world);
    if (!res)
        res = upload_instances(r, world);
    if (!res && r->world_bvh)
        res = upload_bvh(r, world);
    return res;
}

void sb_world_release(struct sb_renderer *r)
{
    struct sb_buffer *buffers[] = {&r->vertices,  &r->bvh_nodes, &r->bvh_triangles,
                                   &r->instances, &r->visible,   &r->emissive};
    for (size_t i = 0; i < sizeof(buffers) / sizeof(buffers[0]); i++)
        sb_buffer_destroy(r->vk, buffers[i]);
    sb_texel_set_destroy(r->vk, &r->textures);
    free(r->caster_boxes);
    free(r->draw_groups);
    free(r->visible_ranges);
    free(r->instance_boxes);
    free(r->caster_instance_boxes);
}
