#include "mesh.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include "io.h"
#include "log.h"
#include "import_mesh.h"
#include "sandbox.h"

/* Node trees deeper than this are refused (a file can make them cyclic). */
#define MESH_MAX_NODE_DEPTH 128

static enum sb_result grow(void **data, size_t *capacity, size_t need, size_t element)
{
    if (need <= *capacity)
        return SB_OK;
    size_t n = *capacity ? *capacity : 64;
    while (n < need)
        n *= 2;
    void *p = realloc(*data, n * element);
    if (!p)
        return SB_ERR_NOMEM;
    *data = p;
    *capacity = n;
    return SB_OK;
}

enum sb_result sb_mesh_add_material(struct sb_mesh *mesh, const char *name, const double albedo[3], uint32_t *index)
{
    if (mesh->material_count >= SB_MESH_MAX_MATERIALS) {
        sb_error("%s: more than %u materials", name, SB_MESH_MAX_MATERIALS);
        return SB_ERR_TOO_LARGE;
    }
    enum sb_result res = grow((void **)&mesh->material_list, &mesh->capacity_materials, mesh->material_count + 1,
                              sizeof(*mesh->material_list));
    if (res)
        return res;
    struct sb_mesh_material *m = &mesh->material_list[mesh->material_count];
    memset(m, 0, sizeof(*m));
    snprintf(m->name, sizeof(m->name), "%s", name);
    for (int c = 0; c < 3; c++)
        m->albedo[c] = (float)fmin(fmax(isfinite(albedo[c]) ? albedo[c] : 0.0, 0.0), 1.0);
    m->roughness = 0.5f;
    m->casts_shadows = true;
    for (int k = 0; k < SB_TEXTURE_SLOT_COUNT; k++)
        m->textures[k] = -1;
    *index = mesh->material_count++;
    return SB_OK;
}

enum sb_result sb_mesh_add_texture(struct sb_mesh *mesh, struct sb_mesh_texture *texture, uint32_t *index)
{
    size_t bytes = sb_texture_bytes(texture);
    for (uint32_t k = 0; k < mesh->texture_count; k++)
        bytes += sb_texture_bytes(&mesh->texture_list[k]);
    enum sb_result res = SB_OK;
    if (mesh->texture_count >= SB_MESH_MAX_TEXTURES || bytes > SB_MESH_MAX_TEXEL_BYTES) {
        sb_error("%s: more than %u images or %llu MiB of texels", texture->name, SB_MESH_MAX_TEXTURES,
                 SB_MESH_MAX_TEXEL_BYTES >> 20);
        res = SB_ERR_TOO_LARGE;
    } else {
        res = grow((void **)&mesh->texture_list, &mesh->capacity_textures, mesh->texture_count + 1,
                   sizeof(*mesh->texture_list));
    }
    if (res) {
        free(texture->rgba);
        texture->rgba = NULL;
        return res;
    }
    mesh->texture_list[mesh->texture_count] = *texture;
    texture->rgba = NULL;
    *index = mesh->texture_count++;
    return SB_OK;
}

enum sb_result sb_mesh_copy_textures(struct sb_mesh *to, const struct sb_mesh *from, uint32_t *base)
{
    *base = to->texture_count;
    for (uint32_t k = 0; k < from->texture_count; k++) {
        struct sb_mesh_texture copy = from->texture_list[k];
        copy.rgba = malloc(sb_texture_bytes(&copy));
        if (!copy.rgba)
            return SB_ERR_NOMEM;
        memcpy(copy.rgba, from->texture_list[k].rgba, sb_texture_bytes(&copy));
        uint32_t index;
        enum sb_result res = sb_mesh_add_texture(to, &copy, &index);
        if (res)
            return res;
    }
    return SB_OK;
}

enum sb_result sb_mesh_copy_material(struct sb_mesh *to, const struct sb_mesh_material *from, uint32_t texture_base,
                                     uint32_t *index)
{
    double albedo[3] = {from->albedo[0], from->albedo[1], from->albedo[2]};
    enum sb_result res = sb_mesh_add_material(to, from->name, albedo, index);
    if (res)
        return res;
    struct sb_mesh_material *m = &to->material_list[*index];
    *m = *from;
    for (int k = 0; k < SB_TEXTURE_SLOT_COUNT; k++)
        m->textures[k] = from->textures[k] < 0 ? -1 : from->textures[k] + (int32_t)texture_base;
    return SB_OK;
}

static bool coordinate_ok(const double p[3])
{
    for (int i = 0; i < 3; i++)
        if (!isfinite(p[i]) || fabs(p[i]) > SB_MESH_MAX_EXTENT_M)
            return false;
    return true;
}

/* Twice the area, from the float coordinates the mesh will hold. */
static double doubled_area(const float *a, const float *b, const float *c)
{
    double e1[3], e2[3];
    for (int i = 0; i < 3; i++) {
        e1[i] = (double)b[i] - a[i];
        e2[i] = (double)c[i] - a[i];
    }
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    return sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

/* A per-vertex array (`components` floats a vertex) that exists once some
 * triangle has it: made (zeros for the vertices before) when `given`,
 * grown with the positions' capacity. */
static enum sb_result grow_attribute(struct sb_mesh *mesh, float **array, size_t components, bool given,
                                     size_t vertices_before)
{
    if (!(*array && mesh->capacity_vertices != vertices_before) && !(given && !*array))
        return SB_OK;
    float *grown = realloc(*array, mesh->capacity_vertices * components * sizeof(float));
    if (!grown)
        return SB_ERR_NOMEM;
    if (!*array)
        memset(grown, 0, (size_t)mesh->vertex_count * components * sizeof(float));
    *array = grown;
    return SB_OK;
}

enum sb_result sb_mesh_add_triangle(struct sb_mesh *mesh, const double a[3], const double b[3], const double c[3],
                                    uint32_t material, const char *source)
{
    return sb_mesh_add_textured_triangle(mesh, a, b, c, NULL, NULL, material, source);
}

enum sb_result sb_mesh_add_textured_triangle(struct sb_mesh *mesh, const double a[3], const double b[3],
                                             const double c[3], const float uv[3][2], const float tangent[3][4],
                                             uint32_t material, const char *source)
{
    const double *v[3] = {a, b, c};
    for (int k = 0; k < 3; k++)
        if (!coordinate_ok(v[k])) {
            sb_error("%s: triangle %u: vertex (%g, %g, %g) is not finite or lies more than %g m from the origin",
                     source, mesh->triangle_count + mesh->dropped_degenerate, v[k][0], v[k][1], v[k][2],
                     SB_MESH_MAX_EXTENT_M);
            return SB_ERR_NUMERIC;
        }
    if (material >= mesh->material_count) {
        sb_error("%s: triangle %u: material %u of %u", source, mesh->triangle_count, material, mesh->material_count);
        return SB_ERR_OUT_OF_RANGE;
    }
    float f[3][3];
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++)
            f[k][i] = (float)v[k][i];
    if (!(doubled_area(f[0], f[1], f[2]) > 0.0)) {
        mesh->dropped_degenerate++;
        return SB_OK;
    }
    if (mesh->triangle_count >= SB_MESH_MAX_TRIANGLES || mesh->vertex_count + 3 > SB_MESH_MAX_VERTICES) {
        sb_error("%s: more than %u triangles", source, SB_MESH_MAX_TRIANGLES);
        return SB_ERR_TOO_LARGE;
    }
    enum sb_result res;
    size_t triangles_before = mesh->capacity_triangles, vertices_before = mesh->capacity_vertices;
    if ((res = grow((void **)&mesh->positions, &mesh->capacity_vertices, (size_t)mesh->vertex_count + 3,
                    3 * sizeof(float))) ||
        (res = grow((void **)&mesh->indices, &mesh->capacity_triangles, (size_t)mesh->triangle_count + 1,
                    3 * sizeof(uint32_t))))
        return res;
    /* materials[] shares the triangles' capacity: grown with it, not at
     * every triangle (a realloc to the same size copies the whole array
     * under AddressSanitizer, which made loading quadratic there) */
    if (mesh->capacity_triangles != triangles_before || !mesh->materials) {
        uint32_t *materials = realloc(mesh->materials, mesh->capacity_triangles * sizeof(uint32_t));
        if (!materials) {
            mesh->capacity_triangles = triangles_before; /* grown again, both, next time */
            return SB_ERR_NOMEM;
        }
        mesh->materials = materials;
    }
    /* uvs[] and tangents[], once a triangle has them, share the vertices' capacity */
    if ((res = grow_attribute(mesh, &mesh->uvs, 2, uv != NULL, vertices_before)) ||
        (res = grow_attribute(mesh, &mesh->tangents, 4, tangent != NULL, vertices_before))) {
        mesh->capacity_vertices = vertices_before; /* every array grown again next time */
        return res;
    }
    for (int k = 0; k < 3 && mesh->uvs; k++)
        for (int i = 0; i < 2; i++)
            mesh->uvs[2 * (size_t)(mesh->vertex_count + k) + i] = uv && isfinite(uv[k][i]) ? uv[k][i] : 0.0f;
    for (int k = 0; k < 3 && mesh->tangents; k++) {
        float *t = &mesh->tangents[4 * (size_t)(mesh->vertex_count + k)];
        double length = 0;
        for (int i = 0; i < 3; i++)
            length += tangent && isfinite(tangent[k][i]) ? (double)tangent[k][i] * tangent[k][i] : 0.0;
        for (int i = 0; i < 3; i++) /* unit, or 0 where there is none */
            t[i] = length > 1e-24 && isfinite(length) ? (float)(tangent[k][i] / sqrt(length)) : 0.0f;
        t[3] = tangent && tangent[k][3] < 0 ? -1.0f : 1.0f;
    }
    for (int k = 0; k < 3; k++) {
        memcpy(&mesh->positions[3 * (size_t)(mesh->vertex_count + k)], f[k], sizeof(f[k]));
        mesh->indices[3 * (size_t)mesh->triangle_count + k] = mesh->vertex_count + k;
    }
    mesh->materials[mesh->triangle_count++] = material;
    mesh->vertex_count += 3;
    return SB_OK;
}

/* ---- assimp ------------------------------------------------------------------------ */

/* 4x4, row-major, column vectors: p' = M p. */
struct mat4 {
    double m[4][4];
};

static struct mat4 mat_mul(const struct mat4 *a, const struct mat4 *b)
{
    struct mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += a->m[i][k] * b->m[k][j];
            r.m[i][j] = s;
        }
    return r;
}

static struct mat4 mat_from_ai(const struct aiMatrix4x4 *t)
{
    return (struct mat4){{{t->a1, t->a2, t->a3, t->a4},
                          {t->b1, t->b2, t->b3, t->b4},
                          {t->c1, t->c2, t->c3, t->c4},
                          {t->d1, t->d2, t->d3, t->d4}}};
}

static struct mat4 mat_identity(void)
{
    return (struct mat4){{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
}

/* The scene's transform (mesh.h) as a matrix applied after the file's own. */
static struct mat4 mat_world(const struct sb_mesh_transform *t)
{
    double s = (t->units_m > 0 ? t->units_m : 1.0) * (t->scale > 0 ? t->scale : 1.0);
    struct mat4 m = mat_identity();
    for (int i = 0; i < 3; i++)
        m.m[i][i] = s;
    if (t->up_z) { /* (x, y, z) -> (x, z, -y) */
        struct mat4 up = {{{1, 0, 0, 0}, {0, 0, 1, 0}, {0, -1, 0, 0}, {0, 0, 0, 1}}};
        m = mat_mul(&up, &m);
    }
    for (int axis = 0; axis < 3; axis++) {
        double r = t->rotate_deg[axis] * (M_PI / 180.0), c = cos(r), sn = sin(r);
        struct mat4 rot = mat_identity();
        int i = (axis + 1) % 3, j = (axis + 2) % 3;
        rot.m[i][i] = c;
        rot.m[i][j] = -sn;
        rot.m[j][i] = sn;
        rot.m[j][j] = c;
        m = mat_mul(&rot, &m);
    }
    for (int i = 0; i < 3; i++)
        m.m[i][3] += t->translate_m[i];
    return m;
}

static void transform_point(const struct mat4 *m, const struct aiVector3D *p, double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = m->m[i][0] * p->x + m->m[i][1] * p->y + m->m[i][2] * p->z + m->m[i][3];
}

void sb_mesh_transform_matrix(const struct sb_mesh_transform *t, double out[3][4])
{
    struct mat4 m = mat_world(t);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            out[r][c] = m.m[r][c];
}

void sb_mesh_transform_point(const struct sb_mesh_transform *t, const double p[3], double out[3])
{
    struct mat4 m = mat_world(t);
    double q[3];
    for (int i = 0; i < 3; i++)
        q[i] = m.m[i][0] * p[0] + m.m[i][1] * p[1] + m.m[i][2] * p[2] + m.m[i][3];
    memcpy(out, q, sizeof(q));
}

struct importer {
    const char *path;
    const struct aiScene *scene;
    const struct sb_mesh_load_params *params;
    struct sb_mesh *mesh;
    uint32_t *material_map; /* the file's material -> the mesh's */
    bool *see_through;      /* the file's material lets light through: its triangles are left out */
    uint64_t see_through_triangles;
    uint64_t triangles; /* counted before anything is added */
    /* kept as parts (sb_mesh_import_parts): each file mesh's part, -1 none */
    struct sb_mesh_parts *parts;
    int32_t *part_of;
    uint32_t *uses;   /* how many times the node tree places each file mesh */
    bool single_only; /* add_node: only the meshes placed once */
    /* the images read so far, by their name in the file and encoding */
    uint32_t image_count;
    struct {
        char name[SB_TEXTURE_NAME_MAX];
        bool srgb;
        uint32_t index;
    } images[SB_MESH_MAX_TEXTURES];
};

/* Count the triangles the node tree instances, refusing deep trees and
 * counts past the cap before any is allocated. */
static enum sb_result count_node(struct importer *im, const struct aiNode *node, int depth)
{
    if (depth > MESH_MAX_NODE_DEPTH) {
        sb_error("%s: the node tree is deeper than %d (cyclic?)", im->path, MESH_MAX_NODE_DEPTH);
        return SB_ERR_MESH;
    }
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        if (node->mMeshes[i] >= im->scene->mNumMeshes) {
            sb_error("%s: node \"%s\" names mesh %u of %u", im->path, node->mName.data, node->mMeshes[i],
                     im->scene->mNumMeshes);
            return SB_ERR_MESH;
        }
        im->triangles += im->scene->mMeshes[node->mMeshes[i]]->mNumFaces;
        if (im->triangles > SB_MESH_MAX_TRIANGLES) {
            sb_error("%s: more than %u triangles (after instancing)", im->path, SB_MESH_MAX_TRIANGLES);
            return SB_ERR_TOO_LARGE;
        }
    }
    enum sb_result res = SB_OK;
    for (unsigned c = 0; c < node->mNumChildren && !res; c++)
        res = count_node(im, node->mChildren[c], depth + 1);
    return res;
}

/* Vertex v's tangent in the world (m's linear part) and its handedness:
 * the sign of (n x t) . b in the file, flipped by a mirroring m. */
static void world_tangent(const struct mat4 *m, const struct aiMesh *am, unsigned v, float out[4])
{
    const struct aiVector3D *t = &am->mTangents[v], *b = &am->mBitangents[v], *n = &am->mNormals[v];
    for (int i = 0; i < 3; i++)
        out[i] = (float)(m->m[i][0] * t->x + m->m[i][1] * t->y + m->m[i][2] * t->z);
    double nxt[3] = {n->y * t->z - n->z * t->y, n->z * t->x - n->x * t->z, n->x * t->y - n->y * t->x};
    double det = m->m[0][0] * (m->m[1][1] * m->m[2][2] - m->m[1][2] * m->m[2][1]) -
                 m->m[0][1] * (m->m[1][0] * m->m[2][2] - m->m[1][2] * m->m[2][0]) +
                 m->m[0][2] * (m->m[1][0] * m->m[2][1] - m->m[1][1] * m->m[2][0]);
    double hand = nxt[0] * b->x + nxt[1] * b->y + nxt[2] * b->z;
    out[3] = (hand < 0) != (det < 0) ? -1.0f : 1.0f;
}

static enum sb_result add_node(struct importer *im, const struct aiNode *node, const struct mat4 *parent)
{
    struct mat4 local = mat_from_ai(&node->mTransformation);
    struct mat4 m = mat_mul(parent, &local);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        const struct aiMesh *am = im->scene->mMeshes[node->mMeshes[i]];
        if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || (im->single_only && im->uses[node->mMeshes[i]] != 1))
            continue;
        uint32_t file_material = am->mMaterialIndex < im->scene->mNumMaterials ? am->mMaterialIndex : 0;
        uint32_t material = im->material_map[file_material];
        if (im->see_through[file_material]) {
            im->see_through_triangles += am->mNumFaces;
            continue;
        }
        /* tangents where a normal map needs them (assimp's, from the texture coordinates) */
        bool tangents = am->mTangents && am->mBitangents && am->mNormals && am->mTextureCoords[0] &&
                        im->mesh->material_list[material].textures[SB_TEXTURE_NORMAL] >= 0;
        for (unsigned f = 0; f < am->mNumFaces; f++) {
            const struct aiFace *face = &am->mFaces[f];
            if (face->mNumIndices != 3)
                continue; /* points and lines */
            double p[3][3];
            float uv[3][2], tangent[3][4];
            const struct aiVector3D *coords = am->mNumUVComponents[0] >= 2 ? am->mTextureCoords[0] : NULL;
            for (int k = 0; k < 3; k++) {
                if (face->mIndices[k] >= am->mNumVertices) {
                    sb_error("%s: mesh \"%s\" face %u: vertex %u of %u", im->path, am->mName.data, f, face->mIndices[k],
                             am->mNumVertices);
                    return SB_ERR_MESH;
                }
                transform_point(&m, &am->mVertices[face->mIndices[k]], p[k]);
                if (coords) {
                    uv[k][0] = (float)coords[face->mIndices[k]].x;
                    uv[k][1] = (float)coords[face->mIndices[k]].y;
                }
                if (tangents)
                    world_tangent(&m, am, face->mIndices[k], tangent[k]);
            }
            enum sb_result res = sb_mesh_add_textured_triangle(im->mesh, p[0], p[1], p[2], coords ? uv : NULL,
                                                               tangents ? tangent : NULL, material, im->path);
            if (res)
                return res;
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; c++) {
        enum sb_result res = add_node(im, node->mChildren[c], &m);
        if (res)
            return res;
    }
    return SB_OK;
}

/* How many times the node tree places each mesh (count_node has checked the tree). */
static void count_uses(struct importer *im, const struct aiNode *node)
{
    for (unsigned i = 0; i < node->mNumMeshes; i++)
        im->uses[node->mMeshes[i]]++;
    for (unsigned c = 0; c < node->mNumChildren; c++)
        count_uses(im, node->mChildren[c]);
}

/* Every placement of a part, the nodes' transforms under `parent`. */
static enum sb_result place_parts(struct importer *im, const struct aiNode *node, const struct mat4 *parent)
{
    struct mat4 local = mat_from_ai(&node->mTransformation);
    struct mat4 m = mat_mul(parent, &local);
    struct sb_mesh_parts *parts = im->parts;
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        int32_t part = im->part_of[node->mMeshes[i]];
        if (part < 0)
            continue;
        if (parts->placement_count >= SB_MESH_MAX_PLACEMENTS) {
            sb_error("%s: more than %u placements of its meshes", im->path, SB_MESH_MAX_PLACEMENTS);
            return SB_ERR_TOO_LARGE;
        }
        if ((parts->placement_count & (parts->placement_count - 1)) == 0) { /* grown at powers of two */
            size_t n = parts->placement_count ? 2 * (size_t)parts->placement_count : 16;
            struct sb_mesh_placement *p = realloc(parts->placements, n * sizeof(*p));
            if (!p)
                return SB_ERR_NOMEM;
            parts->placements = p;
        }
        struct sb_mesh_placement *out = &parts->placements[parts->placement_count++];
        memset(out, 0, sizeof(*out));
        out->part = (uint32_t)part;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++)
                out->to_world[r][c] = m.m[r][c];
    }
    for (unsigned c = 0; c < node->mNumChildren; c++) {
        enum sb_result res = place_parts(im, node->mChildren[c], &m);
        if (res)
            return res;
    }
    return SB_OK;
}

/* The parts: first the meshes placed once, in the file's space (their
 * nodes' transforms applied), as one part placed once; then each mesh
 * placed more than once, in its own space, a part placed where its nodes
 * put it. */
static enum sb_result add_parts(struct importer *im)
{
    const struct aiScene *scene = im->scene;
    struct sb_mesh_parts *parts = im->parts;
    parts->first = calloc(scene->mNumMeshes + 2, sizeof(uint32_t));
    parts->count = calloc(scene->mNumMeshes + 2, sizeof(uint32_t));
    if (!parts->first || !parts->count)
        return SB_ERR_NOMEM;
    static const struct mat4 identity = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    struct mat4 world = mat_world(&im->params->transform);
    im->single_only = true;
    enum sb_result merged = add_node(im, scene->mRootNode, &identity);
    im->single_only = false;
    if (merged)
        return merged;
    if (im->mesh->triangle_count) {
        parts->count[parts->part_count++] = im->mesh->triangle_count;
        parts->placements = calloc(16, sizeof(*parts->placements));
        if (!parts->placements)
            return SB_ERR_NOMEM;
        parts->placement_count = 1;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++)
                parts->placements[0].to_world[r][c] = world.m[r][c];
    }
    for (unsigned i = 0; i < scene->mNumMeshes; i++) {
        im->part_of[i] = -1;
        const struct aiMesh *am = scene->mMeshes[i];
        if (im->uses[i] < 2 || !(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        uint32_t before = im->mesh->triangle_count;
        struct aiNode one = {.mTransformation = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1},
                             .mNumMeshes = 1,
                             .mMeshes = &i};
        enum sb_result res = add_node(im, &one, &identity);
        if (res)
            return res;
        if (im->mesh->triangle_count == before)
            continue; /* nothing but zero-area triangles */
        im->part_of[i] = (int32_t)parts->part_count;
        parts->first[parts->part_count] = before;
        parts->count[parts->part_count++] = im->mesh->triangle_count - before;
    }
    return place_parts(im, scene->mRootNode, &world);
}

/* The image `name` of the file (a path beside it, or "*N", its N-th
 * embedded image) decoded once for each encoding; its index in *index. */
static enum sb_result add_image(struct importer *im, const char *name, bool srgb, const enum aiTextureMapMode mode[2],
                                uint32_t *index)
{
    if (strlen(name) >= SB_TEXTURE_NAME_MAX) {
        sb_error("%s: image %.64s...: a name of %zu bytes; at most %d", im->path, name, strlen(name),
                 SB_TEXTURE_NAME_MAX - 1);
        return SB_ERR_MESH;
    }
    for (uint32_t k = 0; k < im->image_count; k++)
        if (im->images[k].srgb == srgb && !strcmp(im->images[k].name, name)) {
            *index = im->images[k].index;
            return SB_OK;
        }
    if (im->image_count >= SB_MESH_MAX_TEXTURES) {
        sb_error("%s: more than %u images", im->path, SB_MESH_MAX_TEXTURES);
        return SB_ERR_TOO_LARGE;
    }
    struct sb_mesh_texture t = {.srgb = srgb};
    enum sb_result res;
    if (name[0] == '*') {
        char *end;
        unsigned long n = strtoul(name + 1, &end, 10);
        snprintf(t.name, sizeof(t.name), "%.*s", SB_TEXTURE_NAME_MAX - 1, name);
        if (*end || end == name + 1 || n >= im->scene->mNumTextures || !im->scene->mTextures[n]) {
            sb_error("%s: image %s: the file embeds %u images", im->path, name, im->scene->mNumTextures);
            return SB_ERR_MESH;
        }
        const struct aiTexture *at = im->scene->mTextures[n];
        if (at->mHeight == 0) { /* a PNG or JPEG file's bytes */
            res = sb_texture_decode(at->pcData, at->mWidth, im->path, &t);
        } else if (!at->mWidth || at->mWidth > SB_TEXTURE_MAX_SIDE || at->mHeight > SB_TEXTURE_MAX_SIDE) {
            sb_error("%s: image %s: %u x %u texels; images are read up to %u x %u", im->path, name, at->mWidth,
                     at->mHeight, SB_TEXTURE_MAX_SIDE, SB_TEXTURE_MAX_SIDE);
            res = SB_ERR_TOO_LARGE;
        } else { /* texels as assimp holds them: b, g, r, a */
            t.width = at->mWidth;
            t.height = at->mHeight;
            t.rgba = malloc(sb_texture_bytes(&t));
            res = t.rgba ? SB_OK : SB_ERR_NOMEM;
            for (size_t i = 0; !res && i < (size_t)t.width * t.height; i++) {
                const struct aiTexel *x = &at->pcData[i];
                uint8_t *o = &t.rgba[4 * i];
                o[0] = x->r, o[1] = x->g, o[2] = x->b, o[3] = x->a;
            }
        }
    } else {
        res = sb_texture_read(im->path, name, &t);
    }
    if (res) {
        free(t.rgba);
        return res;
    }
    for (int axis = 0; axis < 2; axis++)
        t.wrap[axis] = mode[axis] == aiTextureMapMode_Clamp || mode[axis] == aiTextureMapMode_Decal ? SB_TEXTURE_CLAMP
                       : mode[axis] == aiTextureMapMode_Mirror                                    ? SB_TEXTURE_MIRROR
                                                                                                  : SB_TEXTURE_REPEAT;
    if ((res = sb_mesh_add_texture(im->mesh, &t, index)))
        return res;
    snprintf(im->images[im->image_count].name, sizeof(im->images[0].name), "%.*s", SB_TEXTURE_NAME_MAX - 1, name);
    im->images[im->image_count].srgb = srgb;
    im->images[im->image_count++].index = *index;
    return SB_OK;
}

/* The material's images, glTF's maps as assimp names them. */
static enum sb_result add_textures(struct importer *im, const struct aiMaterial *mat, struct sb_mesh_material *out)
{
    static const struct {
        enum aiTextureType types[2];
        bool srgb;
    } slots[SB_TEXTURE_SLOT_COUNT] = {
        [SB_TEXTURE_BASE_COLOR] = {{aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}, true},
        [SB_TEXTURE_NORMAL] = {{aiTextureType_NORMALS, aiTextureType_NORMALS}, false},
        /* glTF's metallicRoughnessTexture (AI_MATKEY_GLTF_PBRMETALLICROUGHNESS_METALLICROUGHNESS_TEXTURE) */
        [SB_TEXTURE_METALLIC_ROUGHNESS] = {{aiTextureType_UNKNOWN, aiTextureType_UNKNOWN}, false},
        [SB_TEXTURE_EMISSIVE] = {{aiTextureType_EMISSIVE, aiTextureType_EMISSIVE}, true},
    };
    for (int slot = 0; slot < SB_TEXTURE_SLOT_COUNT; slot++)
        for (int k = 0; k < 2 && out->textures[slot] < 0; k++) {
            struct aiString name = {0};
            enum aiTextureMapMode mode[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
            if (aiGetMaterialTextureCount(mat, slots[slot].types[k]) == 0 ||
                aiGetMaterialTexture(mat, slots[slot].types[k], 0, &name, NULL, NULL, NULL, NULL, mode, NULL) !=
                    aiReturn_SUCCESS ||
                !name.length)
                continue;
            uint32_t index;
            enum sb_result res = add_image(im, name.data, slots[slot].srgb, mode, &index);
            if (res)
                return res;
            out->textures[slot] = (int32_t)index;
        }
    struct aiColor4D emissive;
    if (aiGetMaterialColor(mat, AI_MATKEY_COLOR_EMISSIVE, &emissive) == aiReturn_SUCCESS) {
        /* KHR_materials_emissive_strength multiplies the factor */
        ai_real strength = 1;
        if (aiGetMaterialFloat(mat, AI_MATKEY_EMISSIVE_INTENSITY, &strength) != aiReturn_SUCCESS ||
            !(strength >= 0 && strength < 1e6))
            strength = 1;
        float e[3] = {emissive.r * strength, emissive.g * strength, emissive.b * strength};
        for (int c = 0; c < 3; c++)
            out->emissive[c] = isfinite(e[c]) ? fminf(fmaxf(e[c], 0.0f), 1e6f) : 0.0f;
    }
    return SB_OK;
}

static enum sb_result add_materials(struct importer *im)
{
    const struct sb_mesh_load_params *params = im->params;
    unsigned count = im->scene->mNumMaterials ? im->scene->mNumMaterials : 1;
    if (count > SB_MESH_MAX_MATERIALS) {
        sb_error("%s: %u materials, at most %u", im->path, count, SB_MESH_MAX_MATERIALS);
        return SB_ERR_TOO_LARGE;
    }
    im->material_map = calloc(count, sizeof(uint32_t));
    im->see_through = calloc(count, sizeof(bool));
    if (!im->material_map || !im->see_through)
        return SB_ERR_NOMEM;
    for (unsigned i = 0; i < count; i++) {
        const struct aiMaterial *mat = i < im->scene->mNumMaterials ? im->scene->mMaterials[i] : NULL;
        struct aiString name = {0};
        char label[SB_MESH_MATERIAL_NAME_MAX];
        if (mat && aiGetMaterialString(mat, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS && name.length)
            snprintf(label, sizeof(label), "%.*s", (int)sizeof(label) - 1, name.data);
        else
            snprintf(label, sizeof(label), "material%u", i);
        double d = params->default_albedo > 0 ? params->default_albedo : 0.5;
        double albedo[3] = {d, d, d};
        struct aiColor4D color;
        if (mat && (aiGetMaterialColor(mat, AI_MATKEY_BASE_COLOR, &color) == aiReturn_SUCCESS ||
                    aiGetMaterialColor(mat, AI_MATKEY_COLOR_DIFFUSE, &color) == aiReturn_SUCCESS)) {
            albedo[0] = color.r;
            albedo[1] = color.g;
            albedo[2] = color.b;
        }
        for (int o = 0; o < params->override_count; o++) {
            const struct sb_mesh_albedo_override *ov = &params->overrides[o];
            if (!strcmp(ov->material, "*") || !strcmp(ov->material, label))
                memcpy(albedo, ov->albedo, sizeof(albedo));
        }
        enum sb_result res = sb_mesh_add_material(im->mesh, label, albedo, &im->material_map[i]);
        if (res)
            return res;
        /* glTF's metallic-roughness factors, where the file has them */
        struct sb_mesh_material *out = &im->mesh->material_list[im->material_map[i]];
        ai_real value;
        if (mat && aiGetMaterialFloat(mat, AI_MATKEY_ROUGHNESS_FACTOR, &value) == aiReturn_SUCCESS && isfinite(value))
            out->roughness = fminf(fmaxf((float)value, 0.0f), 1.0f);
        if (mat && aiGetMaterialFloat(mat, AI_MATKEY_METALLIC_FACTOR, &value) == aiReturn_SUCCESS && isfinite(value))
            out->metallic = fminf(fmaxf((float)value, 0.0f), 1.0f);
        if (mat && (res = add_textures(im, mat, out)))
            return res;
        /* Glass (an opacity under one half, IFC's and OBJ's; or glTF's
         * transmission over one half) is an opening: the probes' rays and
         * the sun pass it, and nothing draws it (skybake models no
         * refraction, and a pane's few per cent of reflection and
         * absorption are left out) */
        if (mat && ((aiGetMaterialFloat(mat, AI_MATKEY_OPACITY, &value) == aiReturn_SUCCESS && value < 0.5f) ||
                    (aiGetMaterialFloat(mat, AI_MATKEY_TRANSMISSION_FACTOR, &value) == aiReturn_SUCCESS &&
                     value > 0.5f)))
            im->see_through[i] = true;
    }
    return SB_OK;
}

/*
 * assimp's file system in the helper: regular files only, opened without
 * blocking first, so that a FIFO or a device named by the file (an OBJ's
 * mtllib, a glTF's buffer) is refused at once instead of stalling the
 * import until its deadline.
 */
static size_t file_read(struct aiFile *f, char *buffer, size_t size, size_t count)
{
    return fread(buffer, size, count, (FILE *)f->UserData);
}

static size_t file_write(struct aiFile *f, const char *buffer, size_t size, size_t count)
{
    (void)f, (void)buffer, (void)size, (void)count;
    return 0;
}

static size_t file_tell(struct aiFile *f)
{
    long at = ftell((FILE *)f->UserData);
    return at < 0 ? 0 : (size_t)at;
}

static size_t file_size(struct aiFile *f)
{
    struct stat st;
    return fstat(fileno((FILE *)f->UserData), &st) == 0 ? (size_t)st.st_size : 0;
}

static void file_flush(struct aiFile *f)
{
    (void)f;
}

static enum aiReturn file_seek(struct aiFile *f, size_t offset, enum aiOrigin origin)
{
    int whence = origin == aiOrigin_CUR ? SEEK_CUR : origin == aiOrigin_END ? SEEK_END : SEEK_SET;
    return offset <= LONG_MAX && fseek((FILE *)f->UserData, (long)offset, whence) == 0 ? aiReturn_SUCCESS
                                                                                       : aiReturn_FAILURE;
}

static struct aiFile *file_open(struct aiFileIO *io, const char *path, const char *mode)
{
    const char *importing = io->UserData;
    if (strchr(mode, 'w') || strchr(mode, 'a') || strchr(mode, '+'))
        return NULL;
    int fd = sb_open_regular(AT_FDCWD, path, true, NULL);
    if (fd < 0) {
        if (errno == EINVAL)
            sb_error("%s: names %s, which is not a regular file", importing, path);
        return NULL;
    }
    FILE *stream = fdopen(fd, "rb");
    struct aiFile *f = stream ? calloc(1, sizeof(*f)) : NULL;
    if (!f) {
        if (stream)
            fclose(stream);
        else
            close(fd);
        return NULL;
    }
    *f = (struct aiFile){.ReadProc = file_read,
                         .WriteProc = file_write,
                         .TellProc = file_tell,
                         .FileSizeProc = file_size,
                         .SeekProc = file_seek,
                         .FlushProc = file_flush,
                         .UserData = (aiUserData)stream};
    return f;
}

static void file_close(struct aiFileIO *io, struct aiFile *f)
{
    (void)io;
    if (f) {
        fclose((FILE *)f->UserData);
        free(f);
    }
}

/* The import itself, into a fresh mesh, in the helper: the
 * file's materials, then every instanced triangle. */
static enum sb_result import(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh,
                             struct sb_mesh_parts *parts)
{
    struct importer im = {.path = path, .params = params, .mesh = mesh};
    struct aiFileIO io = {.OpenProc = file_open, .CloseProc = file_close, .UserData = (aiUserData)path};
    im.scene =
        aiImportFileEx(path,
                       aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure |
                           aiProcess_CalcTangentSpace,
                       &io);
    enum sb_result res = SB_OK;
    if (!im.scene || !im.scene->mRootNode || (im.scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
        sb_error("%s: assimp cannot read it: %s", path, im.scene ? "the scene is incomplete" : aiGetErrorString());
        res = SB_ERR_MESH;
        goto done;
    }
    if ((res = count_node(&im, im.scene->mRootNode, 0)) || (res = add_materials(&im)))
        goto done;
    bool reused = false;
    if (parts) {
        im.uses = calloc(im.scene->mNumMeshes + 1, sizeof(uint32_t));
        im.part_of = calloc(im.scene->mNumMeshes + 1, sizeof(int32_t));
        if (!im.uses || !im.part_of) {
            res = SB_ERR_NOMEM;
            goto done;
        }
        count_uses(&im, im.scene->mRootNode);
        /* parts when the reuse saves a fifth of the triangles or more: a
         * copy costs a top-level leaf and a moved ray */
        uint64_t unique = 0, placed = 0;
        for (unsigned i = 0; i < im.scene->mNumMeshes; i++) {
            unique += im.uses[i] ? im.scene->mMeshes[i]->mNumFaces : 0;
            placed += (uint64_t)im.uses[i] * im.scene->mMeshes[i]->mNumFaces;
        }
        reused = 4 * placed >= 5 * unique && placed > unique;
    }
    if (reused) {
        im.parts = parts;
        res = add_parts(&im);
    } else {
        struct mat4 world = mat_world(&params->transform);
        res = add_node(&im, im.scene->mRootNode, &world);
    }
    if (res)
        goto done;
    if (im.see_through_triangles)
        sb_info("%s: %llu triangles of see-through materials (glass) left out: light passes them as openings", path,
                (unsigned long long)im.see_through_triangles);
    if (!mesh->triangle_count) {
        sb_error("%s: no triangle of non-zero area (%u left out as degenerate, %llu as see-through)", path,
                 mesh->dropped_degenerate, (unsigned long long)im.see_through_triangles);
        res = SB_ERR_MESH;
    }
done:
    free(im.material_map);
    free(im.see_through);
    free(im.uses);
    free(im.part_of);
    aiReleaseImport(im.scene);
    return res;
}

/* ---- the helper's side and the caller's --------------------------------------------------- */

/*
 * assimp is not hardened: on this machine a PLY header claiming 10^11
 * vertices made it loop for ever, and a reader can crash. So it reads only
 * in a helper program (import_mesh.c, formats/sandbox.h), which sends the
 * mesh back; the parent checks every count against the caps.
 */
#define IMPORT_ADDRESS_SPACE (16ull << 30)

int sb_mesh_import_task(int fd, const void *request, size_t size)
{
    struct sb_import_mesh_request job;
    if (size != sizeof(job))
        return 2;
    memcpy(&job, request, sizeof(job));
    job.path[sizeof(job.path) - 1] = '\0';
    struct sb_mesh_albedo_override overrides[SB_WORLD_MAX_OVERRIDES];
    int override_count = job.override_count >= 0 && job.override_count <= SB_WORLD_MAX_OVERRIDES ? job.override_count : 0;
    for (int o = 0; o < override_count; o++) {
        job.overrides[o].material[sizeof(job.overrides[o].material) - 1] = '\0';
        overrides[o].material = job.overrides[o].material;
        memcpy(overrides[o].albedo, job.overrides[o].albedo, sizeof(overrides[o].albedo));
    }
    struct sb_mesh_load_params params = {
        .transform = job.transform,
        .overrides = overrides,
        .override_count = override_count,
        .default_albedo = job.default_albedo,
    };
    struct sb_import_mesh_answer h = {.magic = SB_IMPORT_MESH_MAGIC};
    sb_sandbox_capture_log(h.message, sizeof(h.message));
    struct sb_mesh mesh = {0};
    struct sb_mesh_parts parts = {0};
    h.result = import(job.path, &params, &mesh, job.keep_parts ? &parts : NULL);
    if (!h.result) {
        h.vertex_count = mesh.vertex_count;
        h.triangle_count = mesh.triangle_count;
        h.material_count = mesh.material_count;
        h.dropped_degenerate = mesh.dropped_degenerate;
        h.part_count = parts.part_count;
        h.placement_count = parts.placement_count;
        h.has_uvs = mesh.uvs != NULL;
        h.has_tangents = mesh.tangents != NULL;
        h.texture_count = mesh.texture_count;
    }
    bool ok = sb_write_all(fd, &h, sizeof(h));
    if (!h.result && ok)
        ok = sb_write_all(fd, mesh.material_list, (size_t)mesh.material_count * sizeof(*mesh.material_list)) &&
             sb_write_all(fd, mesh.positions, (size_t)mesh.vertex_count * 3 * sizeof(float)) &&
             sb_write_all(fd, mesh.materials, (size_t)mesh.triangle_count * sizeof(uint32_t)) &&
             (!mesh.uvs || sb_write_all(fd, mesh.uvs, (size_t)mesh.vertex_count * 2 * sizeof(float))) &&
             (!mesh.tangents || sb_write_all(fd, mesh.tangents, (size_t)mesh.vertex_count * 4 * sizeof(float)));
    for (uint32_t k = 0; !h.result && ok && k < mesh.texture_count; k++)
        ok = sb_write_all(fd, &mesh.texture_list[k], sizeof(mesh.texture_list[k])) &&
             sb_write_all(fd, mesh.texture_list[k].rgba, sb_texture_bytes(&mesh.texture_list[k]));
    for (uint32_t k = 0; !h.result && ok && k < parts.part_count; k++)
        ok = sb_write_all(fd, &parts.first[k], sizeof(uint32_t)) && sb_write_all(fd, &parts.count[k], sizeof(uint32_t));
    if (!h.result && ok && parts.placement_count)
        ok = sb_write_all(fd, parts.placements, parts.placement_count * sizeof(*parts.placements));
    sb_mesh_finish(&mesh);
    sb_mesh_parts_finish(&parts);
    return ok ? 0 : 1;
}

/* A file kept as parts: its ranges of the triangles just received (from
 * `base` on) and its placements, each checked. */
static enum sb_result receive_parts(struct sb_sandbox *box, const char *path, const struct sb_import_mesh_answer *h,
                                    uint32_t base, struct sb_mesh_parts *parts)
{
    if (!parts || h->part_count > h->triangle_count || !h->part_count || !h->placement_count ||
        h->placement_count > SB_MESH_MAX_PLACEMENTS) {
        sb_error("%s: %u parts placed %u times: not what was asked (at most %u placements)", path, h->part_count,
                 h->placement_count, SB_MESH_MAX_PLACEMENTS);
        return SB_ERR_MESH;
    }
    parts->first = malloc(h->part_count * sizeof(uint32_t));
    parts->count = malloc(h->part_count * sizeof(uint32_t));
    parts->placements = malloc(h->placement_count * sizeof(*parts->placements));
    if (!parts->first || !parts->count || !parts->placements)
        return SB_ERR_NOMEM;
    uint32_t next = 0;
    bool read = true;
    for (uint32_t k = 0; k < h->part_count && read; k++) {
        read = sb_sandbox_read(box, &parts->first[k], sizeof(uint32_t)) &&
               sb_sandbox_read(box, &parts->count[k], sizeof(uint32_t));
        /* consecutive, non-empty, covering every triangle */
        if (read && (parts->first[k] != next || !parts->count[k] || parts->count[k] > h->triangle_count - next)) {
            sb_error("%s: part %u: triangles %u + %u of %u, expected from %u", path, k, parts->first[k],
                     parts->count[k], h->triangle_count, next);
            return SB_ERR_MESH;
        }
        next += read ? parts->count[k] : 0;
        parts->first[k] += base;
    }
    read = read && next == h->triangle_count &&
           sb_sandbox_read(box, parts->placements, h->placement_count * sizeof(*parts->placements));
    if (!read) {
        char why[160];
        sb_sandbox_finish(box, why, sizeof(why));
        sb_error("%s: the import's parts stopped half way: its process %s", path, why);
        return SB_ERR_MESH;
    }
    for (uint32_t i = 0; i < h->placement_count; i++) {
        bool finite = parts->placements[i].part < h->part_count;
        for (int r = 0; r < 3 && finite; r++)
            for (int c = 0; c < 4; c++)
                finite = finite && isfinite(parts->placements[i].to_world[r][c]);
        if (!finite) {
            sb_error("%s: placement %u: of no part, or not finite", path, i);
            return SB_ERR_MESH;
        }
    }
    parts->part_count = h->part_count;
    parts->placement_count = h->placement_count;
    return SB_OK;
}

/* Append what the helper sent: the materials, then the triangles through
 * the checks every triangle meets. */
static enum sb_result receive(struct sb_sandbox *box, const char *path, struct sb_mesh *mesh,
                              struct sb_mesh_parts *parts)
{
    uint32_t triangles_before = mesh->triangle_count;
    struct sb_import_mesh_answer h;
    if (!sb_sandbox_read(box, &h, sizeof(h)) || h.magic != SB_IMPORT_MESH_MAGIC) {
        char why[160];
        sb_sandbox_finish(box, why, sizeof(why));
        sb_error("%s: assimp did not finish reading it: its process %s", path, why);
        return SB_ERR_MESH;
    }
    h.message[sizeof(h.message) - 1] = '\0';
    if (h.result) {
        sb_error("%s", h.message[0] ? h.message : "the import failed");
        return (unsigned)h.result < SB_RESULT_COUNT ? (enum sb_result)h.result : SB_ERR_MESH;
    }
    if (h.message[0]) /* what the import said of a file it read all the same */
        sb_warn("%s", h.message);
    if (h.triangle_count > SB_MESH_MAX_TRIANGLES || h.vertex_count != 3 * h.triangle_count ||
        h.material_count > SB_MESH_MAX_MATERIALS || mesh->triangle_count + h.triangle_count > SB_MESH_MAX_TRIANGLES) {
        sb_error("%s: %u triangles, %u materials: past the caps (%u triangles in all, %u materials)", path,
                 h.triangle_count, h.material_count, SB_MESH_MAX_TRIANGLES, SB_MESH_MAX_MATERIALS);
        return SB_ERR_TOO_LARGE;
    }
    if (h.texture_count > SB_MESH_MAX_TEXTURES || h.has_uvs > 1 || h.has_tangents > 1) {
        sb_error("%s: %u images; at most %u", path, h.texture_count, SB_MESH_MAX_TEXTURES);
        return SB_ERR_TOO_LARGE;
    }
    struct sb_mesh_material *materials = malloc((h.material_count + 1) * sizeof(*materials));
    float *positions = malloc((size_t)h.vertex_count * 3 * sizeof(float) + 1);
    uint32_t *triangle_materials = malloc((size_t)h.triangle_count * sizeof(uint32_t) + 1);
    float *uvs = h.has_uvs ? malloc((size_t)h.vertex_count * 2 * sizeof(float) + 1) : NULL;
    float *tangents = h.has_tangents ? malloc((size_t)h.vertex_count * 4 * sizeof(float) + 1) : NULL;
    enum sb_result res = materials && positions && triangle_materials && (uvs || !h.has_uvs) &&
                                 (tangents || !h.has_tangents)
                             ? SB_OK
                             : SB_ERR_NOMEM;
    bool read = !res && sb_sandbox_read(box, materials, h.material_count * sizeof(*materials)) &&
                sb_sandbox_read(box, positions, (size_t)h.vertex_count * 3 * sizeof(float)) &&
                sb_sandbox_read(box, triangle_materials, (size_t)h.triangle_count * sizeof(uint32_t)) &&
                (!uvs || sb_sandbox_read(box, uvs, (size_t)h.vertex_count * 2 * sizeof(float))) &&
                (!tangents || sb_sandbox_read(box, tangents, (size_t)h.vertex_count * 4 * sizeof(float)));
    /* the images, each checked before its texels are allocated */
    uint32_t texture_base = mesh->texture_count;
    size_t texel_bytes = 0;
    for (uint32_t k = 0; k < h.texture_count && read && !res; k++) {
        struct sb_mesh_texture t;
        read = sb_sandbox_read(box, &t, sizeof(t));
        if (!read)
            break;
        t.name[sizeof(t.name) - 1] = '\0';
        texel_bytes += (size_t)4 * (t.width <= SB_TEXTURE_MAX_SIDE ? t.width : 0) *
                       (t.height <= SB_TEXTURE_MAX_SIDE ? t.height : 0);
        if (!t.width || !t.height || t.width > SB_TEXTURE_MAX_SIDE || t.height > SB_TEXTURE_MAX_SIDE ||
            texel_bytes > SB_MESH_MAX_TEXEL_BYTES || t.wrap[0] > SB_TEXTURE_MIRROR || t.wrap[1] > SB_TEXTURE_MIRROR ||
            t.srgb > 1) {
            sb_error("%s: image %s: %u x %u texels, past the caps (%u a side, %llu MiB in all)", path, t.name, t.width,
                     t.height, SB_TEXTURE_MAX_SIDE, SB_MESH_MAX_TEXEL_BYTES >> 20);
            res = SB_ERR_TOO_LARGE;
            break;
        }
        t.rgba = malloc(sb_texture_bytes(&t));
        if (!t.rgba) {
            res = SB_ERR_NOMEM;
            break;
        }
        read = sb_sandbox_read(box, t.rgba, sb_texture_bytes(&t));
        uint32_t index;
        if (!read)
            free(t.rgba);
        else
            res = sb_mesh_add_texture(mesh, &t, &index);
    }
    if (!res && !read) {
        char why[160];
        sb_sandbox_finish(box, why, sizeof(why));
        sb_error("%s: the import stopped half way: its process %s", path, why);
        res = SB_ERR_MESH;
    }
    uint32_t first = mesh->material_count;
    for (uint32_t m = 0; m < h.material_count && !res; m++) {
        materials[m].name[sizeof(materials[m].name) - 1] = '\0';
        /* the helper's values, checked again */
        struct sb_mesh_material *from = &materials[m];
        for (int c = 0; c < 3; c++) {
            from->albedo[c] = isfinite(from->albedo[c]) ? fminf(fmaxf(from->albedo[c], 0.0f), 1.0f) : 0.0f;
            from->emissive[c] = isfinite(from->emissive[c]) ? fminf(fmaxf(from->emissive[c], 0.0f), 1e6f) : 0.0f;
        }
        from->roughness = isfinite(from->roughness) ? fminf(fmaxf(from->roughness, 0.0f), 1.0f) : 0.5f;
        from->metallic = isfinite(from->metallic) ? fminf(fmaxf(from->metallic, 0.0f), 1.0f) : 0.0f;
        from->casts_shadows = true;
        for (int k = 0; k < SB_TEXTURE_SLOT_COUNT; k++)
            if (from->textures[k] < -1 || from->textures[k] >= (int32_t)h.texture_count) {
                sb_error("%s: material %s: image %d of %u", path, from->name, from->textures[k], h.texture_count);
                res = SB_ERR_MESH;
            }
        uint32_t index;
        if (!res)
            res = sb_mesh_copy_material(mesh, from, texture_base, &index);
    }
    uint32_t dropped = mesh->dropped_degenerate;
    for (uint32_t t = 0; t < h.triangle_count && !res; t++) {
        double p[3][3];
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 3; i++)
                p[k][i] = positions[9 * (size_t)t + 3 * k + i];
        if (triangle_materials[t] >= h.material_count) {
            sb_error("%s: triangle %u: material %u of %u", path, t, triangle_materials[t], h.material_count);
            res = SB_ERR_MESH;
            break;
        }
        res = sb_mesh_add_textured_triangle(mesh, p[0], p[1], p[2],
                                            uvs ? (const float(*)[2]) & uvs[6 * (size_t)t] : NULL,
                                            tangents ? (const float(*)[4]) & tangents[12 * (size_t)t] : NULL,
                                            first + triangle_materials[t], path);
    }
    mesh->dropped_degenerate = dropped + h.dropped_degenerate;
    free(materials);
    free(positions);
    free(triangle_materials);
    free(uvs);
    free(tangents);
    if (!res && (h.part_count || h.placement_count) && mesh->triangle_count - triangles_before != h.triangle_count) {
        sb_error("%s: %u of its parts' triangles became zero-area in fp32", path,
                 h.triangle_count - (mesh->triangle_count - triangles_before));
        res = SB_ERR_MESH;
    }
    if (!res && (h.part_count || h.placement_count))
        res = receive_parts(box, path, &h, triangles_before, parts);
    return res;
}

void sb_mesh_parts_finish(struct sb_mesh_parts *parts)
{
    free(parts->first);
    free(parts->count);
    free(parts->placements);
    memset(parts, 0, sizeof(*parts));
}

enum sb_result sb_mesh_import(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh)
{
    return sb_mesh_import_parts(path, params, mesh, NULL);
}

enum sb_result sb_mesh_import_parts(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh,
                                    struct sb_mesh_parts *parts)
{
    static const struct sb_mesh_load_params defaults = {0};
    if (parts)
        memset(parts, 0, sizeof(*parts));
    params = params ? params : &defaults;
    struct stat st;
    if (stat(path, &st) != 0) {
        sb_error("%s: cannot read the mesh: %s", path, strerror(errno));
        return SB_ERR_IO;
    }
    if (!S_ISREG(st.st_mode)) {
        sb_error("%s: not a regular file", path);
        return SB_ERR_IO;
    }
    if ((unsigned long long)st.st_size > SB_MESH_MAX_FILE_BYTES) {
        sb_error("%s: %llu bytes; meshes are read up to %llu MiB", path, (unsigned long long)st.st_size,
                 SB_MESH_MAX_FILE_BYTES >> 20);
        return SB_ERR_TOO_LARGE;
    }
    /* Keep a copy of the counts: a failure leaves *mesh as it was. */
    struct sb_mesh before = *mesh;
    unsigned seconds = params->time_limit_s ? params->time_limit_s : SB_MESH_IMPORT_SECONDS;
    struct sb_sandbox_limits limits = {
        .cpu_seconds = seconds,
        .address_space_bytes = IMPORT_ADDRESS_SPACE,
        .wall_seconds = seconds + 30, /* covers a helper that sleeps; a busy one meets its CPU limit first */
    };
    struct sb_import_mesh_request job = {
        .transform = params->transform,
        .default_albedo = params->default_albedo,
        .override_count = params->override_count,
        .keep_parts = parts != NULL,
    };
    bool fits = snprintf(job.path, sizeof(job.path), "%s", path) < (int)sizeof(job.path) &&
                params->override_count >= 0 && params->override_count <= SB_WORLD_MAX_OVERRIDES;
    for (int o = 0; fits && o < params->override_count; o++) {
        fits = snprintf(job.overrides[o].material, sizeof(job.overrides[o].material), "%s",
                        params->overrides[o].material) < (int)sizeof(job.overrides[o].material);
        memcpy(job.overrides[o].albedo, params->overrides[o].albedo, sizeof(job.overrides[o].albedo));
    }
    if (!fits) {
        sb_error("%s: the path, or the albedo overrides (at most %d, names under 64 bytes), too long to import it",
                 path, SB_WORLD_MAX_OVERRIDES);
        return SB_ERR_TOO_LARGE;
    }
    struct sb_sandbox box;
    enum sb_result res = sb_sandbox_start(&box, &limits, SB_IMPORT_MESH_HELPER, &job, sizeof(job), -1);
    if (res)
        return res;
    res = receive(&box, path, mesh, parts);
    sb_sandbox_finish(&box, NULL, 0);
    if (res && parts)
        sb_mesh_parts_finish(parts);
    if (res) {
        mesh->vertex_count = before.vertex_count;
        mesh->triangle_count = before.triangle_count;
        mesh->material_count = before.material_count;
        mesh->dropped_degenerate = before.dropped_degenerate;
        for (uint32_t k = before.texture_count; k < mesh->texture_count; k++)
            free(mesh->texture_list[k].rgba);
        mesh->texture_count = before.texture_count;
        if (!before.uvs) {
            free(mesh->uvs);
            mesh->uvs = NULL;
        }
        if (!before.tangents) {
            free(mesh->tangents);
            mesh->tangents = NULL;
        }
    } else if (mesh->dropped_degenerate > before.dropped_degenerate) {
        sb_info("%s: %u zero-area triangles left out", path, mesh->dropped_degenerate - before.dropped_degenerate);
    }
    return res;
}

bool sb_mesh_bounds(const struct sb_mesh *mesh, float min[3], float max[3])
{
    if (!mesh->vertex_count)
        return false;
    for (int i = 0; i < 3; i++)
        min[i] = max[i] = mesh->positions[i];
    for (size_t v = 0; v < mesh->vertex_count; v++)
        for (int i = 0; i < 3; i++) {
            min[i] = fminf(min[i], mesh->positions[3 * v + i]);
            max[i] = fmaxf(max[i], mesh->positions[3 * v + i]);
        }
    return true;
}

bool sb_mesh_bounds_casting(const struct sb_mesh *mesh, float min[3], float max[3])
{
    bool any = false;
    for (uint32_t t = 0; t < mesh->triangle_count; t++) {
        if (!mesh->material_list[mesh->materials[t]].casts_shadows)
            continue;
        for (int k = 0; k < 3; k++) {
            const float *p = &mesh->positions[3 * (size_t)mesh->indices[3 * (size_t)t + k]];
            for (int i = 0; i < 3; i++) {
                min[i] = any ? fminf(min[i], p[i]) : p[i];
                max[i] = any ? fmaxf(max[i], p[i]) : p[i];
            }
            any = true;
        }
    }
    return any || sb_mesh_bounds(mesh, min, max);
}

enum sb_result sb_mesh_add_ground(struct sb_mesh *mesh, const struct sb_mesh_ground *ground, const char *source)
{
    float lo[3], hi[3];
    if (!sb_mesh_bounds(mesh, lo, hi))
        return SB_OK;
    if (ground->unless_own) {
        /* upward faces within a millimetre of the lowest point, against the footprint */
        double own = 0.0;
        for (uint32_t t = 0; t < mesh->triangle_count; t++) {
            const float *p[3];
            for (int k = 0; k < 3; k++)
                p[k] = &mesh->positions[3 * (size_t)mesh->indices[3 * (size_t)t + k]];
            if (fmaxf(p[0][1], fmaxf(p[1][1], p[2][1])) > lo[1] + 1e-3f)
                continue;
            /* twice the area projected on the ground, positive facing up */
            double up = ((double)p[2][0] - p[0][0]) * ((double)p[1][2] - p[0][2]) -
                        ((double)p[1][0] - p[0][0]) * ((double)p[2][2] - p[0][2]);
            own += up > 0 ? 0.5 * up : 0.0;
        }
        if (own >= 0.5 * ((double)hi[0] - lo[0]) * ((double)hi[2] - lo[2]))
            return SB_OK;
    }
    double size = ground->size_m;
    if (size <= 0)
        size = fmax(100.0, 4.0 * fmax((double)hi[0] - lo[0], (double)hi[2] - lo[2]));
    size = fmin(size, 2.0 * SB_MESH_MAX_EXTENT_M);
    double y = ground->automatic_height ? fmin(0.0, lo[1]) : ground->height_m;
    /* centred under the model, within the extent the mesh allows */
    double c[2] = {0.5 * ((double)lo[0] + hi[0]), 0.5 * ((double)lo[2] + hi[2])}, h = 0.5 * size;
    for (int i = 0; i < 2; i++)
        c[i] = fmax(fmin(c[i], SB_MESH_MAX_EXTENT_M - h), -SB_MESH_MAX_EXTENT_M + h);
    uint32_t material;
    enum sb_result res = sb_mesh_add_material(mesh, "ground", ground->albedo, &material);
    if (res)
        return res;
    mesh->material_list[material].casts_shadows = false;
    mesh->material_list[material].roughness = 0.9f;
    double p[4][3] = {{c[0] - h, y, c[1] - h}, {c[0] + h, y, c[1] - h}, {c[0] + h, y, c[1] + h}, {c[0] - h, y, c[1] + h}};
    /* counter-clockwise seen from above: facing up */
    if (!(res = sb_mesh_add_triangle(mesh, p[0], p[2], p[1], material, source)))
        res = sb_mesh_add_triangle(mesh, p[0], p[3], p[2], material, source);
    return res;
}

void sb_mesh_hash(const struct sb_mesh *mesh, char out[33])
{
    XXH3_state_t *st = XXH3_createState();
    XXH3_128bits_reset(st);
    XXH3_128bits_update(st, "skybake-mesh-v1", 15);
    uint32_t counts[3] = {mesh->vertex_count, mesh->triangle_count, mesh->material_count};
    XXH3_128bits_update(st, counts, sizeof(counts));
    XXH3_128bits_update(st, mesh->positions, (size_t)mesh->vertex_count * 3 * sizeof(float));
    XXH3_128bits_update(st, mesh->indices, (size_t)mesh->triangle_count * 3 * sizeof(uint32_t));
    XXH3_128bits_update(st, mesh->materials, (size_t)mesh->triangle_count * sizeof(uint32_t));
    for (uint32_t m = 0; m < mesh->material_count; m++)
        XXH3_128bits_update(st, mesh->material_list[m].albedo, sizeof(mesh->material_list[m].albedo));
    /* what only a textured mesh has (an untextured one hashes as before) */
    if (mesh->uvs)
        XXH3_128bits_update(st, mesh->uvs, (size_t)mesh->vertex_count * 2 * sizeof(float));
    if (mesh->tangents)
        XXH3_128bits_update(st, mesh->tangents, (size_t)mesh->vertex_count * 4 * sizeof(float));
    for (uint32_t m = 0; m < mesh->material_count && mesh->texture_count; m++)
        XXH3_128bits_update(st, mesh->material_list[m].textures, sizeof(mesh->material_list[m].textures));
    for (uint32_t k = 0; k < mesh->texture_count; k++) {
        const struct sb_mesh_texture *t = &mesh->texture_list[k];
        uint32_t header[5] = {t->width, t->height, t->wrap[0], t->wrap[1], t->srgb};
        XXH3_128bits_update(st, header, sizeof(header));
        XXH3_128bits_update(st, t->rgba, sb_texture_bytes(t));
    }
    XXH128_hash_t h = XXH3_128bits_digest(st);
    XXH3_freeState(st);
    snprintf(out, 33, "%016llx%016llx", (unsigned long long)h.high64, (unsigned long long)h.low64);
}

void sb_mesh_finish(struct sb_mesh *mesh)
{
    for (uint32_t k = 0; k < mesh->texture_count; k++)
        free(mesh->texture_list[k].rgba);
    free(mesh->texture_list);
    free(mesh->uvs);
    free(mesh->tangents);
    free(mesh->positions);
    free(mesh->indices);
    free(mesh->materials);
    free(mesh->material_list);
    memset(mesh, 0, sizeof(*mesh));
}
