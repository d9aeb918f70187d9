#include "load.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "scene.h"
#include "world_file.h"

bool sb_mesh_is_world_file(const char *path)
{
    size_t length = strlen(path);
    return length > 5 && !strcmp(path + length - 5, ".json");
}

enum sb_result sb_mesh_load(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh)
{
    const char *name = strrchr(path, '/');
    bool world_file = sb_mesh_is_world_file(path);
    if (world_file && params && params->ground) {
        sb_error("%s: a skybake world file states its own ground (its \"ground\"); the scene's world.ground is for "
                 "mesh files",
                 path);
        return SB_ERR_MESH;
    }
    sb_status_begin("loading %s", name ? name + 1 : path);
    enum sb_result res = world_file ? sb_world_file_load(path, params, mesh, NULL) : sb_mesh_import(path, params, mesh);
    if (!res && !world_file && params && params->ground)
        res = sb_mesh_add_ground(mesh, params->ground, path);
    sb_status_end();
    return res;
}

void sb_world_path(const struct sb_world_params *w, const char *directory, char *path, size_t size)
{
    if (w->file[0] == '/' || !directory[0])
        snprintf(path, size, "%s", w->file);
    else
        snprintf(path, size, "%s/%s", directory, w->file);
}

int sb_world_overrides(const struct sb_world_params *w, struct sb_mesh_albedo_override *out)
{
    for (int i = 0; i < w->override_count; i++) {
        out[i].material = w->overrides[i].material;
        memcpy(out[i].albedo, w->overrides[i].albedo, sizeof(out[i].albedo));
    }
    return w->override_count;
}

/* The ground under a file read as parts: found on the parts placed into
 * one mesh (as sb_mesh_load finds it on the flat file), then added to the
 * mesh as one more part, placed once where it lies. */
static enum sb_result ground_part(struct sb_mesh *mesh, struct sb_mesh_parts *parts, const struct sb_mesh_ground *ground,
                                  const char *path)
{
    struct sb_mesh placed = {0};
    uint32_t material;
    enum sb_result res = sb_mesh_add_material(&placed, "placed", (double[3]){0, 0, 0}, &material);
    for (uint32_t i = 0; i < parts->placement_count && !res; i++) {
        const struct sb_mesh_placement *at = &parts->placements[i];
        for (uint32_t t = parts->first[at->part]; t < parts->first[at->part] + parts->count[at->part] && !res; t++) {
            double p[3][3];
            for (int k = 0; k < 3; k++) {
                const float *v = &mesh->positions[3 * (size_t)mesh->indices[3 * (size_t)t + k]];
                for (int r = 0; r < 3; r++)
                    p[k][r] = at->to_world[r][0] * v[0] + at->to_world[r][1] * v[1] + at->to_world[r][2] * v[2] +
                              at->to_world[r][3];
            }
            res = sb_mesh_add_triangle(&placed, p[0], p[1], p[2], material, path);
        }
    }
    uint32_t before = placed.triangle_count;
    if (!res)
        res = sb_mesh_add_ground(&placed, ground, path);
    if (!res && placed.triangle_count > before) {
        const struct sb_mesh_material *from = &placed.material_list[placed.material_count - 1];
        uint32_t index, first = mesh->triangle_count;
        res = sb_mesh_copy_material(mesh, from, 0, &index);
        for (uint32_t t = before; t < placed.triangle_count && !res; t++) {
            double p[3][3];
            for (int k = 0; k < 3; k++)
                for (int r = 0; r < 3; r++)
                    p[k][r] = placed.positions[3 * (size_t)placed.indices[3 * (size_t)t + k] + r];
            res = sb_mesh_add_triangle(mesh, p[0], p[1], p[2], index, path);
        }
        uint32_t *f = res ? NULL : realloc(parts->first, (parts->part_count + 1) * sizeof(uint32_t));
        uint32_t *c = f ? realloc(parts->count, (parts->part_count + 1) * sizeof(uint32_t)) : NULL;
        if (f)
            parts->first = f;
        if (c)
            parts->count = c;
        struct sb_mesh_placement *pl =
            c ? realloc(parts->placements, (parts->placement_count + 1) * sizeof(*parts->placements)) : NULL;
        if (!res && !pl)
            res = SB_ERR_NOMEM;
        if (!res) {
            parts->placements = pl;
            parts->first[parts->part_count] = first;
            parts->count[parts->part_count] = mesh->triangle_count - first;
            parts->placements[parts->placement_count++] =
                (struct sb_mesh_placement){.part = parts->part_count++, .to_world = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
        }
    }
    sb_mesh_finish(&placed);
    return res;
}

static enum sb_result load_world(const struct sb_world_params *w, const char *directory, struct sb_mesh *mesh,
                                 struct sb_mesh_parts *parts, char *path_out, size_t path_size)
{
    char path[2100];
    sb_world_path(w, directory, path, sizeof(path));
    struct sb_mesh_albedo_override overrides[SB_WORLD_MAX_OVERRIDES];
    sb_world_overrides(w, overrides);
    struct sb_mesh_ground ground = {
        .unless_own = !w->ground.object,
        .automatic_height = !w->ground.has_height,
        .height_m = w->ground.height_m,
        .size_m = w->ground.size_m,
        .albedo = {w->ground.albedo[0], w->ground.albedo[1], w->ground.albedo[2]},
    };
    struct sb_mesh_load_params load = {
        .transform = {.units_m = w->units_m, .scale = w->scale, .up_z = w->up_z},
        .overrides = overrides,
        .override_count = w->override_count,
        /* a world file states its own */
        .ground = w->ground.none || sb_mesh_is_world_file(path) ? NULL : &ground,
    };
    memcpy(load.transform.rotate_deg, w->rotate_deg, sizeof(w->rotate_deg));
    memcpy(load.transform.translate_m, w->translate_m, sizeof(w->translate_m));
    enum sb_result res;
    if (parts && !sb_mesh_is_world_file(path)) {
        const char *name = strrchr(path, '/');
        sb_status_begin("loading %s", name ? name + 1 : path);
        res = sb_mesh_import_parts(path, &load, mesh, parts);
        sb_status_end();
        if (!res && load.ground && parts->part_count)
            res = ground_part(mesh, parts, load.ground, path);
        else if (!res && load.ground)
            res = sb_mesh_add_ground(mesh, load.ground, path);
        if (res)
            sb_mesh_parts_finish(parts);
    } else {
        if (parts)
            memset(parts, 0, sizeof(*parts));
        res = sb_mesh_load(path, &load, mesh);
    }
    if (!res && path_out) {
        char *absolute = realpath(path, NULL);
        snprintf(path_out, path_size, "%s", absolute ? absolute : path);
        free(absolute);
    }
    return res;
}

enum sb_result sb_mesh_load_world(const struct sb_world_params *w, const char *directory, struct sb_mesh *mesh,
                                  char *path_out, size_t path_size)
{
    return load_world(w, directory, mesh, NULL, path_out, path_size);
}

enum sb_result sb_mesh_load_world_parts(const struct sb_world_params *w, const char *directory, struct sb_mesh *mesh,
                                        struct sb_mesh_parts *parts, char *path_out, size_t path_size)
{
    return load_world(w, directory, mesh, parts, path_out, path_size);
}
