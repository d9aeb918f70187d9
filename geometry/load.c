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

enum sb_result sb_mesh_load_world(const struct sb_world_params *w, const char *directory, struct sb_mesh *mesh,
                                  char *path_out, size_t path_size)
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
    enum sb_result res = sb_mesh_load(path, &load, mesh);
    if (!res && path_out) {
        char *absolute = realpath(path, NULL);
        snprintf(path_out, path_size, "%s", absolute ? absolute : path);
        free(absolute);
    }
    return res;
}
