#include "level.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include "load.h"
#include "log.h"
#include "scene.h"
#include "splitmix.h"
#include "world_file.h"

/* A file a world file places, where: its unique entry, its placement in
 * the placing file's space. */
struct child {
    uint32_t unique;
    double local[3][4];
};

/* A file read once, however often placed. */
struct unique {
    char path[PATH_MAX]; /* absolute, symbolic links resolved */
    int32_t mesh;        /* its own triangles' mesh in the level, -1: none */
    struct child *children;
    uint32_t child_count;
    uint64_t instances, triangles; /* what one copy of it places, itself included */
    bool resolving;                /* on the path being read: placing it again is a cycle */
};

struct loader {
    struct sb_level *level;
    struct unique *uniques;
    uint32_t unique_count, unique_capacity, mesh_capacity;
    const struct sb_mesh_load_params *import; /* the scene's overrides, no placement */
};

static void mat_mul(const double a[3][4], const double b[3][4], double out[3][4])
{
    double r[3][4];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 4; j++)
            r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + (j == 3 ? a[i][3] : 0.0);
    }
    memcpy(out, r, sizeof(r));
}

static const double identity[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

static enum sb_result add_mesh(struct loader *ld, struct sb_mesh *mesh, int32_t *index)
{
    struct sb_level *l = ld->level;
    if (l->mesh_count == ld->mesh_capacity) {
        uint32_t n = ld->mesh_capacity ? 2 * ld->mesh_capacity : 8;
        struct sb_mesh *m = realloc(l->meshes, n * sizeof(*m));
        if (!m)
            return SB_ERR_NOMEM;
        l->meshes = m;
        ld->mesh_capacity = n;
    }
    *index = (int32_t)l->mesh_count;
    l->meshes[l->mesh_count++] = *mesh;
    memset(mesh, 0, sizeof(*mesh));
    return SB_OK;
}

/* A new unique entry named `path` (no mesh, no children yet). */
static enum sb_result new_unique(struct loader *ld, const char *path, uint32_t *index)
{
    if (ld->unique_count == ld->unique_capacity) {
        uint32_t n = ld->unique_capacity ? 2 * ld->unique_capacity : 16;
        struct unique *u = realloc(ld->uniques, n * sizeof(*u));
        if (!u)
            return SB_ERR_NOMEM;
        ld->uniques = u;
        ld->unique_capacity = n;
    }
    *index = ld->unique_count++;
    struct unique *u = &ld->uniques[*index];
    memset(u, 0, sizeof(*u));
    snprintf(u->path, sizeof(u->path), "%s", path);
    u->mesh = -1;
    return SB_OK;
}

/* A mesh file whose nodes place a mesh more than once (mesh.h's parts):
 * each part a mesh of its own (every material kept, so that the indices
 * hold) and an entry "path#k" placed as the file's children. */
static enum sb_result add_parts(struct loader *ld, uint32_t self, const struct sb_mesh *mesh,
                                const struct sb_mesh_parts *parts)
{
    struct child *children = calloc(parts->placement_count, sizeof(*children));
    uint32_t *part_unique = calloc(parts->part_count, sizeof(*part_unique));
    enum sb_result res = children && part_unique ? SB_OK : SB_ERR_NOMEM;
    for (uint32_t k = 0; k < parts->part_count && !res; k++) {
        struct sb_mesh part = {0};
        uint32_t texture_base = 0;
        res = sb_mesh_copy_textures(&part, mesh, &texture_base);
        for (uint32_t m = 0; m < mesh->material_count && !res; m++)
            res = sb_mesh_copy_material(&part, &mesh->material_list[m], texture_base, &(uint32_t){0});
        for (uint32_t t = parts->first[k]; t < parts->first[k] + parts->count[k] && !res; t++) {
            double p[3][3];
            float uv[3][2], tangent[3][4];
            for (int v = 0; v < 3; v++) {
                uint32_t vertex = mesh->indices[3 * (size_t)t + v];
                for (int i = 0; i < 3; i++)
                    p[v][i] = mesh->positions[3 * (size_t)vertex + i];
                for (int i = 0; i < 2 && mesh->uvs; i++)
                    uv[v][i] = mesh->uvs[2 * (size_t)vertex + i];
                for (int i = 0; i < 4 && mesh->tangents; i++)
                    tangent[v][i] = mesh->tangents[4 * (size_t)vertex + i];
            }
            res = sb_mesh_add_textured_triangle(&part, p[0], p[1], p[2], mesh->uvs ? uv : NULL,
                                                mesh->tangents ? tangent : NULL, mesh->materials[t],
                                                ld->uniques[self].path);
        }
        char name[PATH_MAX + 16];
        snprintf(name, sizeof(name), "%s#%u", ld->uniques[self].path, k);
        int32_t mesh_index = -1;
        if (!res && !(res = add_mesh(ld, &part, &mesh_index)) && !(res = new_unique(ld, name, &part_unique[k]))) {
            struct unique *u = &ld->uniques[part_unique[k]];
            u->mesh = mesh_index;
            u->instances = 1;
            u->triangles = ld->level->meshes[mesh_index].triangle_count;
        }
        sb_mesh_finish(&part);
    }
    for (uint32_t i = 0; i < parts->placement_count && !res; i++) {
        children[i].unique = part_unique[parts->placements[i].part];
        memcpy(children[i].local, parts->placements[i].to_world, sizeof(children[i].local));
    }
    free(part_unique);
    if (res) {
        free(children);
        return res;
    }
    ld->uniques[self].children = children;
    ld->uniques[self].child_count = parts->placement_count;
    return SB_OK;
}

static enum sb_result resolve(struct loader *ld, const char *path, uint32_t depth, const char *named_by,
                              uint32_t *out);

/* What a world file's scatters land on: its own triangles and what its
 * first `instances` children (its "instances" list) place, their own
 * triangles, as one BVH (built once for all its scatters). */
static enum sb_result landing(struct loader *ld, const struct unique *u, uint32_t instances, const char *source,
                              struct sb_bvh *bvh)
{
    const struct sb_level *l = ld->level;
    const struct sb_mesh **meshes = malloc((instances + 1) * sizeof(*meshes));
    struct sb_bvh_instance *placed = malloc((instances + 1) * sizeof(*placed));
    enum sb_result res = meshes && placed ? SB_OK : SB_ERR_NOMEM;
    uint32_t mesh_count = 0, placed_count = 0;
    for (uint32_t c = 0; c <= instances && !res; c++) {
        int32_t m = c == 0 ? u->mesh : ld->uniques[u->children[c - 1].unique].mesh;
        if (m < 0)
            continue;
        uint32_t k = 0; /* each mesh once */
        while (k < mesh_count && meshes[k] != &l->meshes[m])
            k++;
        if (k == mesh_count)
            meshes[mesh_count++] = &l->meshes[m];
        placed[placed_count].mesh = k;
        const void *to_world = c == 0 ? (const void *)identity : (const void *)u->children[c - 1].local;
        memcpy(placed[placed_count++].to_world, to_world, sizeof(identity));
    }
    if (!res && !placed_count) {
        sb_error("%s: scatter: nothing to land on (the file has no triangles of its own and no instances)", source);
        res = SB_ERR_MESH;
    }
    if (!res)
        res = sb_bvh_build_instanced(meshes, mesh_count, placed, placed_count, bvh);
    free(meshes);
    free(placed);
    return res;
}

/* A scatter's copies, each dropped from 10 km up onto `surface`. */
static void scatter(const struct sb_bvh *surface, const struct sb_world_file_ref *r, const char *source,
                    struct child *out)
{
    uint64_t state = r->seed * 0x2545f4914f6cdd1dull + 1;
    uint32_t missed = 0;
    for (uint32_t i = 0; i < r->count; i++) {
        double x = r->area_m[0] + sb_splitmix_uniform(&state) * (r->area_m[2] - r->area_m[0]);
        double z = r->area_m[1] + sb_splitmix_uniform(&state) * (r->area_m[3] - r->area_m[1]);
        double yaw = 360.0 * sb_splitmix_uniform(&state);
        double s = r->scale_range[0] + sb_splitmix_uniform(&state) * (r->scale_range[1] - r->scale_range[0]);
        float o[3] = {(float)x, (float)SB_MESH_MAX_EXTENT_M, (float)z}, d[3] = {0, -1, 0};
        struct sb_hit hit;
        double y = 0.0;
        if (sb_bvh_intersect(surface, o, d, 0.0f, (float)(2 * SB_MESH_MAX_EXTENT_M), false, &hit))
            y = SB_MESH_MAX_EXTENT_M - hit.t;
        else
            missed++;
        struct sb_mesh_transform t = r->transform;
        t.scale = s;
        t.rotate_deg[0] = t.rotate_deg[2] = 0.0;
        t.rotate_deg[1] = yaw;
        t.translate_m[0] = x;
        t.translate_m[1] = y;
        t.translate_m[2] = z;
        sb_mesh_transform_matrix(&t, out[i].local);
    }
    if (missed)
        sb_warn("%s: scatter of %s: %u of %u copies found nothing below them and stand at y = 0", source, r->file,
                missed, r->count);
}

/* Read a world file's own triangles and what it places. */
static enum sb_result read_world_file(struct loader *ld, uint32_t self, uint32_t depth)
{
    struct sb_mesh mesh = {0};
    struct sb_world_file_refs refs = {0};
    char path[PATH_MAX];
    snprintf(path, sizeof(path), "%s", ld->uniques[self].path);
    enum sb_result res = sb_world_file_load(path, ld->import, &mesh, &refs);
    if (!res && mesh.triangle_count)
        res = add_mesh(ld, &mesh, &ld->uniques[self].mesh);
    sb_mesh_finish(&mesh);
    uint64_t copies = 0;
    for (int i = 0; i < refs.count; i++)
        copies += refs.refs[i].scatter ? refs.refs[i].count : 1;
    if (!res && copies > SB_LEVEL_MAX_INSTANCES) {
        sb_error("%s: places %llu copies: over the cap of %u instances", path, (unsigned long long)copies,
                 SB_LEVEL_MAX_INSTANCES);
        res = SB_ERR_TOO_LARGE;
    }
    struct child *children = res ? NULL : calloc(copies ? copies : 1, sizeof(*children));
    if (!res && !children)
        res = SB_ERR_NOMEM;
    char dir[PATH_MAX];
    snprintf(dir, sizeof(dir), "%s", path);
    *strrchr(dir, '/') = '\0';
    /* the instances first: the scatters land on them */
    uint32_t n = 0, instances = 0;
    struct sb_bvh surface = {0};
    for (int pass = 0; pass < 2 && !res; pass++) {
        if (pass == 1)
            instances = n;
        for (int i = 0; i < refs.count && !res; i++) {
            const struct sb_world_file_ref *r = &refs.refs[i];
            if (r->scatter != (pass == 1))
                continue;
            char named[PATH_MAX + 32], child_path[2 * PATH_MAX];
            snprintf(named, sizeof(named), "%s: %s", path, r->scatter ? "scatter" : "instances");
            snprintf(child_path, sizeof(child_path), "%s%s%s", r->file[0] == '/' ? "" : dir, r->file[0] == '/' ? "" : "/",
                     r->file);
            uint32_t unique;
            if ((res = resolve(ld, child_path, depth + 1, named, &unique)))
                break;
            struct unique *u = &ld->uniques[self];
            u->children = children;
            u->child_count = n;
            if (!r->scatter) {
                children[n].unique = unique;
                sb_mesh_transform_matrix(&r->transform, children[n++].local);
            } else {
                if (!surface.nodes)
                    res = landing(ld, u, instances, path, &surface);
                if (!res)
                    scatter(&surface, r, path, &children[n]);
                for (uint32_t k = 0; k < r->count && !res; k++)
                    children[n + k].unique = unique;
                n += r->count;
            }
        }
    }
    sb_bvh_finish(&surface);
    struct unique *u = &ld->uniques[self];
    u->children = children;
    u->child_count = res ? 0 : n;
    free(refs.refs);
    return res;
}

/* The unique entry of the file at `path` (read and resolved the first time
 * it is met), for a copy placed `depth` files deep. */
static enum sb_result resolve(struct loader *ld, const char *path, uint32_t depth, const char *named_by, uint32_t *out)
{
    char canonical[PATH_MAX];
    if (!realpath(path, canonical)) {
        sb_error("%s: cannot read %s: %s", named_by, path, strerror(errno));
        return SB_ERR_IO;
    }
    for (uint32_t i = 0; i < ld->unique_count; i++) {
        if (strcmp(ld->uniques[i].path, canonical))
            continue;
        if (ld->uniques[i].resolving) {
            sb_error("%s: %s places itself (a cycle of world files)", named_by, canonical);
            return SB_ERR_MESH;
        }
        *out = i;
        return SB_OK;
    }
    if (depth > SB_LEVEL_MAX_DEPTH) {
        sb_error("%s: %s: world files nest more than %d deep", named_by, canonical, SB_LEVEL_MAX_DEPTH);
        return SB_ERR_TOO_LARGE;
    }
    uint32_t self;
    enum sb_result res = new_unique(ld, canonical, &self);
    if (res)
        return res;
    struct unique *u = &ld->uniques[self];
    u->resolving = true;
    if (sb_mesh_is_world_file(canonical)) {
        res = read_world_file(ld, self, depth);
    } else {
        struct sb_mesh mesh = {0};
        struct sb_mesh_parts parts;
        const char *name = strrchr(canonical, '/');
        sb_status_begin("loading %s", name ? name + 1 : canonical);
        res = sb_mesh_import_parts(canonical, ld->import, &mesh, &parts);
        sb_status_end();
        if (!res && !parts.part_count)
            res = add_mesh(ld, &mesh, &ld->uniques[self].mesh);
        else if (!res)
            res = add_parts(ld, self, &mesh, &parts);
        sb_mesh_finish(&mesh);
        sb_mesh_parts_finish(&parts);
    }
    u = &ld->uniques[self];
    u->resolving = false;
    if (res)
        return res;
    /* what one copy places, checked against the caps as it grows */
    u->instances = u->mesh >= 0;
    u->triangles = u->mesh >= 0 ? ld->level->meshes[u->mesh].triangle_count : 0;
    for (uint32_t c = 0; c < u->child_count; c++) {
        const struct unique *child = &ld->uniques[u->children[c].unique];
        u->instances += child->instances;
        u->triangles += child->triangles;
        if (u->instances > SB_LEVEL_MAX_INSTANCES || u->triangles > SB_LEVEL_MAX_PLACED_TRIANGLES) {
            sb_error("%s: places over %u instances or %llu triangles (the caps)", canonical, SB_LEVEL_MAX_INSTANCES,
                     (unsigned long long)SB_LEVEL_MAX_PLACED_TRIANGLES);
            return SB_ERR_TOO_LARGE;
        }
    }
    *out = self;
    return SB_OK;
}

static void place(struct loader *ld, uint32_t unique, const double to_world[3][4])
{
    const struct unique *u = &ld->uniques[unique];
    struct sb_level *l = ld->level;
    if (u->mesh >= 0) {
        struct sb_bvh_instance *in = &l->instances[l->instance_count++];
        in->mesh = (uint32_t)u->mesh;
        memcpy(in->to_world, to_world, sizeof(in->to_world));
        l->placed_triangles += l->meshes[u->mesh].triangle_count;
    }
    for (uint32_t c = 0; c < u->child_count; c++) {
        double m[3][4];
        mat_mul(to_world, u->children[c].local, m);
        place(ld, u->children[c].unique, m);
    }
}

static bool casting_bounds(const struct sb_level *level, float min[3], float max[3]);

enum sb_result sb_level_load(const struct sb_world_params *w, const char *directory, struct sb_level *level,
                             char *path_out, size_t path_size)
{
    memset(level, 0, sizeof(*level));
    char path[2100];
    sb_world_path(w, directory, path, sizeof(path));
    struct sb_mesh_albedo_override overrides[SB_WORLD_MAX_OVERRIDES];
    struct sb_mesh_load_params import = {.overrides = overrides, .override_count = sb_world_overrides(w, overrides)};
    struct loader ld = {.level = level, .import = &import};
    struct sb_mesh top = {0};
    struct sb_world_file_refs refs = {0};
    enum sb_result res;
    if (sb_mesh_is_world_file(path)) {
        /* a world file that places nothing is the one mesh it always was */
        struct sb_mesh_load_params params = import;
        params.transform = (struct sb_mesh_transform){.units_m = w->units_m, .scale = w->scale, .up_z = w->up_z};
        memcpy(params.transform.rotate_deg, w->rotate_deg, sizeof(w->rotate_deg));
        memcpy(params.transform.translate_m, w->translate_m, sizeof(w->translate_m));
        const char *name = strrchr(path, '/');
        sb_status_begin("loading %s", name ? name + 1 : path);
        res = sb_world_file_load(path, &params, &top, &refs);
        sb_status_end();
        if (!res && !refs.count && !top.triangle_count) {
            sb_error("%s: no triangle (no ground, no object, nothing placed)", path);
            res = SB_ERR_MESH;
        }
        if (!res && refs.count) {
            /* the world file itself is the first unique entry: placing it again is a cycle */
            char canonical[PATH_MAX];
            struct unique *u = NULL;
            if (!realpath(path, canonical)) {
                sb_error("%s: %s", path, strerror(errno));
                res = SB_ERR_IO;
            } else if (!(ld.uniques = calloc(16, sizeof(*ld.uniques)))) {
                res = SB_ERR_NOMEM;
            } else {
                ld.unique_capacity = 16;
                ld.unique_count = 1;
                u = &ld.uniques[0];
                snprintf(u->path, sizeof(u->path), "%s", canonical);
                u->mesh = -1;
                u->resolving = true;
                free(refs.refs);
                memset(&refs, 0, sizeof(refs));
                sb_mesh_finish(&top);
                /* read again, in its own space, with what it places */
                res = read_world_file(&ld, 0, 0);
                ld.uniques[0].resolving = false;
            }
            if (!res) {
                u = &ld.uniques[0];
                uint64_t instances = u->mesh >= 0, triangles = 0;
                for (uint32_t c = 0; c < u->child_count; c++) {
                    instances += ld.uniques[u->children[c].unique].instances;
                    triangles += ld.uniques[u->children[c].unique].triangles;
                }
                if (instances > SB_LEVEL_MAX_INSTANCES || triangles > SB_LEVEL_MAX_PLACED_TRIANGLES) {
                    sb_error("%s: places %llu instances, %llu triangles: over the caps (%u, %llu)", path,
                             (unsigned long long)instances, (unsigned long long)triangles, SB_LEVEL_MAX_INSTANCES,
                             (unsigned long long)SB_LEVEL_MAX_PLACED_TRIANGLES);
                    res = SB_ERR_TOO_LARGE;
                }
                level->instances = res ? NULL : calloc(instances ? instances : 1, sizeof(*level->instances));
                if (!res && !level->instances)
                    res = SB_ERR_NOMEM;
                if (!res) {
                    double to_world[3][4];
                    sb_mesh_transform_matrix(&params.transform, to_world);
                    place(&ld, 0, to_world);
                }
            }
        } else if (!res) {
            res = add_mesh(&ld, &top, &(int32_t){0});
        }
        free(refs.refs);
        sb_mesh_finish(&top);
    } else {
        /* a mesh file: one mesh, or parts when its nodes reuse meshes (a
         * glTF's wheels), placed where the scene puts it, on its ground */
        struct sb_mesh_parts parts;
        res = sb_mesh_load_world_parts(w, directory, &top, &parts, NULL, 0);
        if (!res && !parts.part_count) {
            res = add_mesh(&ld, &top, &(int32_t){0});
        } else if (!res) {
            char canonical[PATH_MAX];
            if (!realpath(path, canonical)) {
                sb_error("%s: %s", path, strerror(errno));
                res = SB_ERR_IO;
            } else if ((res = new_unique(&ld, canonical, &(uint32_t){0})) ||
                       (res = add_parts(&ld, 0, &top, &parts))) {
                /* nothing placed */
            } else if (!(level->instances = calloc(parts.placement_count, sizeof(*level->instances)))) {
                res = SB_ERR_NOMEM;
            } else {
                place(&ld, 0, identity);
            }
        }
        sb_mesh_parts_finish(&parts);
        sb_mesh_finish(&top);
    }
    for (uint32_t i = 0; i < ld.unique_count; i++)
        free(ld.uniques[i].children);
    free(ld.uniques);
    uint64_t unique_triangles = 0, materials = 0;
    for (uint32_t m = 0; m < level->mesh_count; m++) {
        unique_triangles += level->meshes[m].triangle_count;
        materials += level->meshes[m].material_count;
    }
    if (!res && (unique_triangles >= SB_BVH_BACK_FACE || materials >= SB_BVH_BACK_FACE)) {
        sb_error("%s: %llu unique triangles: past 2^31", path, (unsigned long long)unique_triangles);
        res = SB_ERR_TOO_LARGE;
    }
    uint64_t textures = 0;
    for (uint32_t m = 0; m < level->mesh_count; m++)
        textures += level->meshes[m].texture_count;
    level->materials = res ? NULL : malloc((materials ? materials : 1) * sizeof(*level->materials));
    level->textures = res ? NULL : malloc((textures ? textures : 1) * sizeof(*level->textures));
    if (!res && (!level->materials || !level->textures))
        res = SB_ERR_NOMEM;
    for (uint32_t m = 0; m < level->mesh_count && !res; m++) {
        const struct sb_mesh *mesh = &level->meshes[m];
        for (uint32_t k = 0; k < mesh->material_count; k++) {
            struct sb_mesh_material *to = &level->materials[level->material_count + k];
            *to = mesh->material_list[k];
            for (int slot = 0; slot < SB_TEXTURE_SLOT_COUNT; slot++)
                to->textures[slot] += to->textures[slot] < 0 ? 0 : (int32_t)level->texture_count;
        }
        for (uint32_t k = 0; k < mesh->texture_count; k++)
            level->textures[level->texture_count + k] = &mesh->texture_list[k];
        level->material_count += mesh->material_count;
        level->texture_count += mesh->texture_count;
    }
    if (!res && !level->instance_count)
        level->placed_triangles = level->meshes[0].triangle_count;
    if (!res)
        level->has_casting_bounds = casting_bounds(level, level->casting_min, level->casting_max);
    if (!res && path_out) {
        char *absolute = realpath(path, NULL);
        snprintf(path_out, path_size, "%s", absolute ? absolute : path);
        free(absolute);
    }
    if (!res && level->instance_count)
        sb_info("%s: %u meshes (%llu triangles) placed %u times: %llu triangles", path, level->mesh_count,
                (unsigned long long)unique_triangles, level->instance_count,
                (unsigned long long)level->placed_triangles);
    if (res)
        sb_level_finish(level);
    return res;
}

void sb_level_finish(struct sb_level *level)
{
    for (uint32_t m = 0; m < level->mesh_count; m++)
        sb_mesh_finish(&level->meshes[m]);
    free(level->meshes);
    free(level->instances);
    free(level->materials);
    free(level->textures);
    memset(level, 0, sizeof(*level));
}

enum sb_result sb_level_build_bvh(const struct sb_level *level, struct sb_bvh *bvh)
{
    if (!level->instance_count)
        return sb_bvh_build(&level->meshes[0], bvh);
    const struct sb_mesh **meshes = malloc(level->mesh_count * sizeof(*meshes));
    if (!meshes) {
        memset(bvh, 0, sizeof(*bvh));
        return SB_ERR_NOMEM;
    }
    for (uint32_t m = 0; m < level->mesh_count; m++)
        meshes[m] = &level->meshes[m];
    enum sb_result res = sb_bvh_build_instanced(meshes, level->mesh_count, level->instances, level->instance_count, bvh);
    free(meshes);
    return res;
}

void sb_level_hash(const struct sb_level *level, char out[33])
{
    if (!level->instance_count) {
        sb_mesh_hash(&level->meshes[0], out);
        return;
    }
    XXH3_state_t *st = XXH3_createState();
    XXH3_128bits_reset(st);
    for (uint32_t m = 0; m < level->mesh_count; m++) {
        char h[33];
        sb_mesh_hash(&level->meshes[m], h);
        XXH3_128bits_update(st, h, 32);
    }
    for (uint32_t i = 0; i < level->instance_count; i++) { /* field by field: no padding */
        XXH3_128bits_update(st, &level->instances[i].mesh, sizeof(level->instances[i].mesh));
        XXH3_128bits_update(st, level->instances[i].to_world, sizeof(level->instances[i].to_world));
    }
    XXH128_hash_t h = XXH3_128bits_digest(st);
    XXH3_freeState(st);
    snprintf(out, 33, "%016llx%016llx", (unsigned long long)h.high64, (unsigned long long)h.low64);
}

/* Grow lo, hi by instance `in`'s triangles (those that cast shadows, or
 * all), placed vertex by vertex, as the flattened level would hold them
 * (a box's corners placed would grow a turned part's box); false when it
 * adds none. */
static bool grow_placed(const struct sb_mesh *mesh, const struct sb_bvh_instance *in, bool casters, bool any,
                        float lo[3], float hi[3])
{
    bool added = false;
    for (uint32_t t = 0; t < mesh->triangle_count; t++) {
        if (casters && !mesh->material_list[mesh->materials[t]].casts_shadows)
            continue;
        for (int k = 0; k < 3; k++) {
            const float *p = &mesh->positions[3 * (size_t)mesh->indices[3 * (size_t)t + k]];
            for (int r = 0; r < 3; r++) {
                float w = (float)(in->to_world[r][0] * p[0] + in->to_world[r][1] * p[1] + in->to_world[r][2] * p[2] +
                                  in->to_world[r][3]);
                lo[r] = any || added ? fminf(lo[r], w) : w;
                hi[r] = any || added ? fmaxf(hi[r], w) : w;
            }
            added = true;
        }
    }
    return added;
}

bool sb_level_bounds_casting(const struct sb_level *level, float min[3], float max[3])
{
    memcpy(min, level->casting_min, sizeof(level->casting_min));
    memcpy(max, level->casting_max, sizeof(level->casting_max));
    return level->has_casting_bounds;
}

/* The bounds sb_level_bounds_casting returns, found once as the level is read. */
static bool casting_bounds(const struct sb_level *level, float min[3], float max[3])
{
    if (!level->instance_count)
        return sb_mesh_bounds_casting(&level->meshes[0], min, max);
    /* the casters (a mesh file's ground, a part of its own, casts
     * nothing), else every triangle, as sb_mesh_bounds_casting */
    bool any = false;
    for (int casters = 1; casters >= 0 && !any; casters--)
        for (uint32_t i = 0; i < level->instance_count; i++)
            any |= grow_placed(&level->meshes[level->instances[i].mesh], &level->instances[i], casters, any, min, max);
    return any;
}

/* A tangent placed by an instance (NULL: in place): its direction by the
 * linear part, its handedness flipped by a mirror. */
static void place_tangent(const struct sb_bvh_instance *in, const float t[4], float out[4])
{
    if (!in) {
        memcpy(out, t, 4 * sizeof(float));
        return;
    }
    const double(*m)[4] = in->to_world;
    for (int r = 0; r < 3; r++)
        out[r] = (float)(m[r][0] * t[0] + m[r][1] * t[1] + m[r][2] * t[2]);
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    out[3] = det < 0 ? -t[3] : t[3];
}

enum sb_result sb_level_flatten(const struct sb_level *level, struct sb_mesh *mesh)
{
    memset(mesh, 0, sizeof(*mesh));
    if (level->placed_triangles > SB_MESH_MAX_TRIANGLES) {
        sb_error("the world places %llu triangles: drawn as one list, at most %u", 
                 (unsigned long long)level->placed_triangles, SB_MESH_MAX_TRIANGLES);
        return SB_ERR_TOO_LARGE;
    }
    enum sb_result res = SB_OK;
    uint32_t first_material = 0;
    uint32_t *material_base = calloc(level->mesh_count + 1, sizeof(*material_base));
    if (!material_base)
        return SB_ERR_NOMEM;
    for (uint32_t m = 0; m < level->mesh_count && !res; m++) {
        material_base[m] = first_material;
        uint32_t texture_base = 0;
        res = sb_mesh_copy_textures(mesh, &level->meshes[m], &texture_base);
        for (uint32_t k = 0; k < level->meshes[m].material_count && !res; k++) {
            uint32_t index;
            res = sb_mesh_copy_material(mesh, &level->meshes[m].material_list[k], texture_base, &index);
            if (!res)
                first_material = index + 1;
        }
    }
    uint32_t count = level->instance_count ? level->instance_count : 1;
    for (uint32_t i = 0; i < count && !res; i++) {
        const struct sb_bvh_instance *in = level->instance_count ? &level->instances[i] : NULL;
        const struct sb_mesh *from = &level->meshes[in ? in->mesh : 0];
        for (uint32_t t = 0; t < from->triangle_count && !res; t++) {
            double p[3][3];
            float uv[3][2], tangent[3][4];
            for (int k = 0; k < 3; k++) {
                uint32_t vertex = from->indices[3 * (size_t)t + k];
                for (int c = 0; c < 2 && from->uvs; c++)
                    uv[k][c] = from->uvs[2 * (size_t)vertex + c];
                if (from->tangents)
                    place_tangent(in, &from->tangents[4 * (size_t)vertex], tangent[k]);
                const float *v = &from->positions[3 * (size_t)vertex];
                for (int r = 0; r < 3; r++)
                    p[k][r] = in ? in->to_world[r][0] * v[0] + in->to_world[r][1] * v[1] + in->to_world[r][2] * v[2] +
                                       in->to_world[r][3]
                                 : v[r];
            }
            res = sb_mesh_add_textured_triangle(mesh, p[0], p[1], p[2], from->uvs ? uv : NULL,
                                                from->tangents ? tangent : NULL,
                                                material_base[in ? in->mesh : 0] + from->materials[t], "the world");
        }
    }
    free(material_base);
    if (res)
        sb_mesh_finish(mesh);
    return res;
}

/* ---- shared while held ---------------------------------------------------------------------- */

static struct {
    pthread_mutex_t lock;
    struct sb_level level;
    struct sb_world_params world;
    char directory[1024], path[PATH_MAX];
    int holders;
} shared = {.lock = PTHREAD_MUTEX_INITIALIZER};

enum sb_result sb_level_acquire(const struct sb_world_params *world, const char *directory,
                                const struct sb_level **level, char *path_out, size_t path_size)
{
    *level = NULL;
    pthread_mutex_lock(&shared.lock);
    enum sb_result res = SB_OK;
    bool same = shared.holders && !memcmp(&shared.world, world, sizeof(*world)) &&
                !strcmp(shared.directory, directory);
    if (!same && shared.holders) {
        /* another world while one is held: read alone, not shared */
        pthread_mutex_unlock(&shared.lock);
        struct sb_level *own = malloc(sizeof(*own));
        if (!own)
            return SB_ERR_NOMEM;
        if ((res = sb_level_load(world, directory, own, path_out, path_size)))
            free(own);
        else
            *level = own;
        return res;
    }
    if (!same) {
        res = sb_level_load(world, directory, &shared.level, shared.path, sizeof(shared.path));
        if (!res) {
            memcpy(&shared.world, world, sizeof(*world));
            snprintf(shared.directory, sizeof(shared.directory), "%s", directory);
        }
    }
    if (!res) {
        shared.holders++;
        *level = &shared.level;
        if (path_out)
            snprintf(path_out, path_size, "%s", shared.path);
    }
    pthread_mutex_unlock(&shared.lock);
    return res;
}

void sb_level_release(const struct sb_level **level)
{
    if (!*level)
        return;
    pthread_mutex_lock(&shared.lock);
    if (*level == &shared.level) {
        if (--shared.holders == 0)
            sb_level_finish(&shared.level);
    } else {
        struct sb_level *own = (struct sb_level *)*level;
        sb_level_finish(own);
        free(own);
    }
    pthread_mutex_unlock(&shared.lock);
    *level = NULL;
}
