#include "load.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "scene.h"
#include "world_file.h"

enum sb_result sb_mesh_load(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh)
{
    size_t length = strlen(path);
    const char *name = strrchr(path, '/');
    sb_status_begin("loading %s", name ? name + 1 : path);
    enum sb_result res = length > 5 && !strcmp(path + length - 5, ".json") ? sb_world_file_load(path, params, mesh)
                                                                            : sb_mesh_import(path, params, mesh);
    sb_status_end();
    return res;
}

enum sb_result sb_mesh_load_world(const struct sb_world_params *w, const char *directory, struct sb_mesh *mesh,
                                  char *path_out, size_t path_size)
{
    char path[2100];
    if (w->file[0] == '/' || !directory[0])
        snprintf(path, sizeof(path), "%s", w->file);
    else
        snprintf(path, sizeof(path), "%s/%s", directory, w->file);
    struct sb_mesh_albedo_override overrides[SB_WORLD_MAX_OVERRIDES];
    for (int i = 0; i < w->override_count; i++) {
        overrides[i].material = w->overrides[i].material;
        memcpy(overrides[i].albedo, w->overrides[i].albedo, sizeof(overrides[i].albedo));
    }
    struct sb_mesh_load_params load = {
        .transform = {.units_m = w->units_m, .scale = w->scale, .up_z = w->up_z},
        .overrides = overrides,
        .override_count = w->override_count,
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
