/*
 * Scene geometry as the baker sees it: one triangle soup in world space
 * (metres, y up, the runtime's convention), each triangle with a material
 * (a name and a linear albedo). Meshes come from files through assimp
 * (glTF 2.0, GLB, OBJ, PLY, IFC and the other formats it reads) or from
 * code (the runtime's procedural test world, the tests' analytic shapes)
 * through sb_mesh_add_triangle; both paths meet the same checks.
 *
 * Everything a file could make huge is checked before it is allocated:
 * the file's size, then assimp's counts against the caps below.
 */
#ifndef SB_GEOMETRY_MESH_H
#define SB_GEOMETRY_MESH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "result.h"
#include "mesh_texture.h"

/* Caps: a mesh file larger than this is refused before it is read. */
#define SB_MESH_MAX_FILE_BYTES (512ull << 20)
/* Triangles and vertices a mesh may hold (a BVH node index fits in 31 bits). */
#define SB_MESH_MAX_TRIANGLES (16u << 20)
#define SB_MESH_MAX_VERTICES (48u << 20)
#define SB_MESH_MAX_MATERIALS 4096
#define SB_MESH_MATERIAL_NAME_MAX 64
/* Coordinates beyond this many metres from the origin (after the
 * transform) are refused: fp32 steps there are 1 mm. */
#define SB_MESH_MAX_EXTENT_M 1.0e4
/* assimp imports in a helper process (it is not hardened against hostile
 * files: one made it loop for ever here) under this CPU-time limit, 16 GiB
 * of address space beyond the helper's own, and a wall-clock deadline 30 s past
 * the CPU limit (formats/sandbox.h); files the mesh names (an OBJ's mtllib,
 * a glTF's buffers) must be regular files. */
#define SB_MESH_IMPORT_SECONDS 300

struct sb_mesh_material {
    char name[SB_MESH_MATERIAL_NAME_MAX];
    float albedo[3];    /* linear, [0, 1] */
    float roughness;    /* perceptual, [0, 1]: for the runtime's shading [0.5] */
    float metallic;     /* [0, 1] [0] */
    bool casts_shadows; /* false: receives only (a ground plane) [true] */
    float emissive[3];  /* linear radiance factor [0] */
    /* The images the material reads (mesh_texture.h's slots): indices in the
     * mesh's texture_list, -1 none [-1]. The base colour's multiplies
     * albedo, as glTF's baseColorTexture does its factor. */
    int32_t textures[SB_TEXTURE_SLOT_COUNT];
};

struct sb_mesh {
    uint32_t vertex_count, triangle_count, material_count;
    float *positions;                       /* owned: 3 per vertex, metres */
    uint32_t *indices;                      /* owned: 3 per triangle, < vertex_count */
    uint32_t *materials;                    /* owned: one per triangle, < material_count */
    struct sb_mesh_material *material_list; /* owned */
    uint32_t dropped_degenerate;            /* zero-area triangles left out on loading */
    /* Texture coordinates, 2 a vertex (u right, v up from the image's last
     * row, as OpenGL has them; assimp turns glTF's over),
     * or NULL when no triangle has them (0, 0 for those without). */
    float *uvs;
    /* Tangents, 4 a vertex: the unit direction of increasing u (world), w
     * +1 or -1, the handedness of (normal, tangent, bitangent) (glTF's);
     * or NULL when no triangle has them (0, 0, 0, 1 for those without). */
    float *tangents;
    uint32_t texture_count;
    struct sb_mesh_texture *texture_list; /* owned, each with its texels */
    size_t capacity_vertices, capacity_triangles, capacity_materials, capacity_textures;
};

/* How a file's coordinates become world coordinates: p_world = translate +
 * R(rotate) * (scale * units_m * p_file), R the rotations about x, then y,
 * then z (degrees), after assimp has applied the file's own node transforms
 * and, for a z-up file (up_z), turned z-up into y-up. Zero means default:
 * units_m and scale 0 read as 1. */
struct sb_mesh_transform {
    double units_m; /* metres per file unit [1] */
    double scale;   /* [1] */
    double rotate_deg[3];
    double translate_m[3];
    bool up_z; /* the file is z-up (turn +z to +y) */
};

/* A material's albedo given by the scene instead of the file's. */
struct sb_mesh_albedo_override {
    const char *material; /* the material's name in the file, or "*" for every material */
    double albedo[3];
};

/* The ground a model from a mesh file stands on (a skybake world file
 * states its own): a square, upward, that receives shadows and casts none
 * (material "ground"), so that the model shades it and the probes see it. */
struct sb_mesh_ground {
    bool unless_own;       /* none when the model has a ground of its own: upward faces at its lowest
                              point covering half its footprint or more */
    bool automatic_height; /* at the model's lowest point or 0 (the planet's ground), the lower */
    double height_m;       /* else here */
    double size_m;         /* its side; 0: 4 times the model's larger horizontal extent, at least 100 m */
    double albedo[3];      /* linear */
};

struct sb_mesh_load_params {
    struct sb_mesh_transform transform;
    /* For a mesh file: the ground it stands on, or NULL for none. A world
     * file with one is refused (it states its own). */
    const struct sb_mesh_ground *ground;
    const struct sb_mesh_albedo_override *overrides;
    int override_count;
    /* Albedo of a material whose file gives no base or diffuse colour [0.5]. */
    double default_albedo;
    /* CPU seconds the import may take [SB_MESH_IMPORT_SECONDS]. */
    unsigned time_limit_s;
};

/* A file whose nodes place one mesh more than once, kept as its parts
 * (sb_mesh_import_parts): part k is triangles [first[k], first[k] +
 * count[k]) of the mesh, in its own space; each placement puts a part in
 * the world. */
#define SB_MESH_MAX_PLACEMENTS (1u << 20)
struct sb_mesh_placement {
    uint32_t part;
    uint32_t pad;
    double to_world[3][4];
};
struct sb_mesh_parts {
    uint32_t part_count, placement_count;
    uint32_t *first, *count;               /* owned */
    struct sb_mesh_placement *placements; /* owned */
};

/*
 * Append the triangles of the mesh file at `path`, read through assimp, to
 * *mesh (which may hold triangles already, or be zeroed). Every triangle of
 * every mesh of the file's node tree, with the nodes' transforms; points
 * and lines are left out; polygons are triangulated. Materials take the
 * file's base colour (glTF's baseColorFactor) or else its diffuse colour,
 * clamped to [0, 1], unless an override names them. load.h's sb_mesh_load
 * also reads skybake world files; most callers want that.
 *
 * Refuses, naming the file and the reason, and leaving *mesh as it was: a
 * file that cannot be read or is over SB_MESH_MAX_FILE_BYTES
 * (SB_ERR_IO, SB_ERR_TOO_LARGE), one assimp refuses, crashes on or does
 * not finish within the time limit (SB_ERR_MESH), a
 * non-finite or out-of-extent coordinate (SB_ERR_NUMERIC), counts past the
 * caps (SB_ERR_TOO_LARGE), and a file with no triangle of non-zero area
 * (SB_ERR_MESH). Zero-area triangles are left out and counted.
 */
enum sb_result sb_mesh_import(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh);

/*
 * As sb_mesh_import, but a file whose node tree places some mesh more than
 * once (a glTF's wheels), saving a fifth of its triangles or more, comes
 * as parts into an empty *mesh: the meshes placed once as one part, in the
 * file's space, then each mesh placed more than once as a part, in its own
 * space; every placement of a part (the nodes' transforms and params'
 * placement) in *parts. Any other file comes as sb_mesh_import reads it,
 * parts->part_count 0 (a copy costs a top-level leaf and a moved ray: the
 * IFC house's few reused meshes are not worth it).
 * At most SB_MESH_MAX_PLACEMENTS placements. Free parts with
 * sb_mesh_parts_finish.
 */
enum sb_result sb_mesh_import_parts(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh,
                                    struct sb_mesh_parts *parts);
void sb_mesh_parts_finish(struct sb_mesh_parts *parts);

/* The transform as rows of an affine 3 x 4 (file units to world metres). */
void sb_mesh_transform_matrix(const struct sb_mesh_transform *t, double out[3][4]);

/* Where the transform takes point p (file units) in world metres. */
void sb_mesh_transform_point(const struct sb_mesh_transform *t, const double p[3], double out[3]);

/* Add a material (roughness 0.5, metallic 0, casting shadows: set the
 * fields afterwards to change them); returns its index in *index. */
enum sb_result sb_mesh_add_material(struct sb_mesh *mesh, const char *name, const double albedo[3], uint32_t *index);

/* Append one triangle (world space, metres) with material `material`.
 * Refuses non-finite or out-of-extent coordinates; a zero-area triangle is
 * dropped (counted) and SB_OK returned. `source` names the caller in
 * messages. */
enum sb_result sb_mesh_add_triangle(struct sb_mesh *mesh, const double a[3], const double b[3], const double c[3],
                                    uint32_t material, const char *source);

/* As sb_mesh_add_triangle, with the vertices' texture coordinates (uv[k]
 * for vertex k; NULL: none, read as 0) and tangents (tangent[k]: a
 * direction, normalised here, and the handedness's sign; NULL: none). */
enum sb_result sb_mesh_add_textured_triangle(struct sb_mesh *mesh, const double a[3], const double b[3],
                                             const double c[3], const float uv[3][2], const float tangent[3][4],
                                             uint32_t material, const char *source);

/* Add a texture, taking its texels (texture->rgba then belongs to the
 * mesh, also on failure); its index in *index. Refuses more than
 * SB_MESH_MAX_TEXTURES or SB_MESH_MAX_TEXEL_BYTES in all. */
enum sb_result sb_mesh_add_texture(struct sb_mesh *mesh, struct sb_mesh_texture *texture, uint32_t *index);

/* Copy every texture of `from` into `to` (texels too); *base gets the
 * index of the first copy, the offset for the materials' indices. */
enum sb_result sb_mesh_copy_textures(struct sb_mesh *to, const struct sb_mesh *from, uint32_t *base);

/* Copy material `from` into `to` (after sb_mesh_copy_textures, whose base
 * offsets its textures); its index in *index. */
enum sb_result sb_mesh_copy_material(struct sb_mesh *to, const struct sb_mesh_material *from, uint32_t texture_base,
                                     uint32_t *index);

/* The bounds of every vertex; false when the mesh is empty. */
bool sb_mesh_bounds(const struct sb_mesh *mesh, float min[3], float max[3]);

/* The bounds of the triangles that cast shadows (what stands on a ground),
 * else of every vertex; false when the mesh is empty. */
bool sb_mesh_bounds_casting(const struct sb_mesh *mesh, float min[3], float max[3]);

/* Add `ground` under everything the mesh holds (sb_mesh_ground);
 * `source` names the model in messages. */
enum sb_result sb_mesh_add_ground(struct sb_mesh *mesh, const struct sb_mesh_ground *ground, const char *source);

/* XXH3-128 of the positions, indices, materials and albedos, and where
 * the mesh has them its texture coordinates, tangents, materials' textures
 * and texels (an untextured mesh hashes as before textures): what a bake
 * that reads the mesh depends on. */
void sb_mesh_hash(const struct sb_mesh *mesh, char out[33]);

/* Free the arrays and zero *mesh; accepts a zeroed mesh. */
void sb_mesh_finish(struct sb_mesh *mesh);

#endif
