/*
 * Inside skyview's renderer: the state its passes share, and the interface a
 * pass implements. A frame records the passes of sb_pass_classes in order;
 * adding a pass is a file that defines its class, an entry in enum sb_pass
 * (renderer.h) and one in that table (renderer.c).
 *
 * A pass's create hook makes what it owns, adds it to the render graph's
 * table of resources (graph.h), and declares what it uses of the table,
 * through which bindings of config.h's SB_VIEW_BINDING_*; the graph gives
 * it its own descriptor set and the barriers before it.
 */
#ifndef SB_RUNTIME_RENDERER_INTERNAL_H
#define SB_RUNTIME_RENDERER_INTERNAL_H

#include "compute.h"
#include "config.h"
#include "graph.h"
#include "renderer.h"
#include "shadows.h"
#include "texture.h"
#include "transform.h"

struct sb_clouds;
struct sb_fog;
struct sb_grade;
struct sb_local_tonemap;
struct sb_purkinje;
struct sb_image;

#define SB_HDR_FORMAT VK_FORMAT_R16G16B16A16_SFLOAT
#define SB_DEPTH_FORMAT VK_FORMAT_D32_SFLOAT
#define SB_BLOOM_SETS (2 * SB_BLOOM_MAX_LEVELS)
_Static_assert(SB_BLOOM_SETS <= SB_GRAPH_MAX_SETS, "a bloom step a set");

enum compute_kernel {
    KERNEL_SKY_VIEW,
    KERNEL_AERIAL,
    KERNEL_SKY,            /* the camera inside the atmosphere */
    KERNEL_SKY_FROM_SPACE, /* above it */
    KERNEL_HISTOGRAM,
    KERNEL_EXPOSURE,
    KERNEL_BLOOM_DOWN,
    KERNEL_BLOOM_UP,
    KERNEL_TONEMAP,
    KERNEL_PROBE_SKY,
    KERNEL_PROBE_LIGHT,
    KERNEL_COUNT,
};

struct sb_renderer {
    struct sb_vk *vk;
    struct sb_renderer_params params;
    const struct sb_pack *pack; /* during sb_renderer_create only */
    uint32_t width, height, bloom_levels;
    uint32_t vertex_count, caster_first_vertex;
    struct sb_caster_box *caster_boxes; /* shadows.h */
    unsigned caster_box_count;
    int32_t cascade_clear[SB_CASCADES][4]; /* this frame's texels to clear and draw in each cascade */
    double radiance_scale;                 /* 1 / the sun's largest channel: radiance in units of the sun */
    double frame_scale;                    /* this frame's: what stored radiance is multiplied by, the
                                              radiance scale times the pre-exposure (renderer.c) */
    double previous_frame_scale;           /* the last frame's, which its history was stored with */
    double next_frame_scale;               /* the next frame's, from this frame's exposure */
    double readback_scale;                 /* the frame scale of the last frame read back */
    double ground_radius_km;
    float thickness_km;                    /* the atmosphere's, as the shaders hold it */
    bool camera_in_atmosphere;             /* this frame's: which sky kernel runs */
    double world_min_m[3], world_max_m[3]; /* the world's box */
    bool aerial_volume_only;               /* this frame's: which scene pipeline draws */
    bool scene_traced;                     /* the scene pass traces (scene_trace.c): no cascades to draw */

    struct sb_buffer atmosphere;
    struct sb_texture transmittance, multiscattering, irradiance_ground; /* RGBA32F: the LUT; the refined and
                                                                            lookup forms (physics.h) */
    struct sb_buffer frame, vertices, exposure;
    struct sb_buffer probes, probe_light;           /* sb_probes_gpu and its probes; the sky's and probes' SH */
    struct sb_buffer reflections, reflection_cubes; /* sb_reflections_gpu, its probes and the DFG; the cubes */
    uint32_t probe_count;                           /* grid probes lit by the probes pass (0: none) */
    uint32_t reflection_count;                      /* reflection probes the scene reads (0: none) */
    struct sb_buffer read_ldr, read_hdr, read_sky_view;
    struct sb_buffer read_post;  /* the HDR frame after post-processing, when post_in_place */
    bool post_in_place;          /* a post-processing pass writes the HDR frame (from the graph) */
    int first_post;              /* the first post-processing pass: the lit frame is whole before it */
    struct sb_buffer post_input; /* params.post_input as halves, or none */

    struct sb_texture sky_view, aerial, aerial_t, shadow, hdr, depth, bloom, ldr;
    VkSampler linear, nearest, shadow_compare, repeat; /* repeat: linear, wrapping (tileable noise) */

    struct sb_graph graph; /* graph.h */
    int pass;              /* the pass being created or recorded */
    sb_resource hdr_id, ldr_id, sky_view_id;
    VkPipeline kernels[KERNEL_COUNT];
    VkPipeline shadow_pipeline, scene_pipeline;
    VkPipeline scene_volume_pipeline;          /* aerial perspective from its volume alone (aerial.glsl) */
    VkPipeline scene_trace[2];                 /* traced: generic, aerial perspective from its volume alone */
    struct sb_buffer bvh_nodes, bvh_triangles; /* the world's BVH when traced */

    struct sb_fog *fog;                     /* fog.c */
    struct sb_clouds *clouds;               /* clouds.c */
    struct sb_grade *grade;                 /* grade.c */
    struct sb_purkinje *purkinje;           /* purkinje.c */
    struct sb_local_tonemap *local_tonemap; /* local_tonemap.c */

    VkQueryPool queries;
    VkCommandBuffer cmd;
    VkFence fence;
    const struct sb_view *view; /* the frame being recorded */
    uint64_t frame_index;       /* frames rendered before this one */
    struct sb_mat4 view_proj;   /* of the last frame, camera-relative */
    double camera_m[3];
};

/* A pass: hooks called in sb_pass_classes' order. `create` (may be NULL)
 * makes what the pass owns, adds it to the graph's table and declares its
 * uses (graph.h); `destroy` (may be NULL) frees it and accepts a partly
 * created pass; `record` adds the pass's commands to r->cmd (its
 * timestamps and the barriers before it are the renderer's). */
struct sb_pass_class {
    const char *name; /* in timing tables */
    /* Post-processing: it takes the lit frame, which is whole before the
     * first such pass (readback, params.post_input). */
    bool post;
    enum sb_result (*create)(struct sb_renderer *r);
    void (*destroy)(struct sb_renderer *r);
    void (*record)(struct sb_renderer *r);
    /* The frame is whole without it, so a view may leave it out
     * (sb_view.disabled_passes); `skipped` (may be NULL) is called instead
     * of `record` then, e.g. to drop a history that would go stale. */
    bool optional;
    void (*skipped)(struct sb_renderer *r);
    /* Bits 1 << SB_PASS_x of the optional passes whose output this one
     * reads: with any of them left out, this one is left out too. */
    uint32_t needs;
};

/* scene_trace.c: whether to trace the scene; the BVH (none when not
 * traced); the traced scene pass's uses and kernels, and a frame of it. */
bool sb_scene_trace_wanted(const struct sb_renderer_params *params, const struct sb_vk *vk, uint32_t vertex_count);
enum sb_result sb_scene_trace_create(struct sb_renderer *r, const struct sb_world *world);
enum sb_result sb_scene_trace_create_pass(struct sb_renderer *r);
void sb_scene_trace_destroy(struct sb_renderer *r);
void sb_scene_trace_record(struct sb_renderer *r);

extern const struct sb_pass_class sb_pass_fog;           /* fog.c: the froxel volume */
extern const struct sb_pass_class sb_pass_fog_apply;     /* fog.c: the volume applied to the frame */
extern const struct sb_pass_class sb_pass_cloud_shadow;  /* clouds.c: the clouds' shadow map */
extern const struct sb_pass_class sb_pass_clouds;        /* clouds.c: traced, resolved, composited */
extern const struct sb_pass_class sb_pass_purkinje;      /* purkinje.c: the rods' shift in dim light */
extern const struct sb_pass_class sb_pass_local_tonemap; /* local_tonemap.c: base and detail on a bilateral grid */
extern const struct sb_pass_class sb_pass_grade_linear;  /* grade.c: scene-linear grading (and its resources) */
extern const struct sb_pass_class sb_pass_grade;         /* grade.c: the LUT on the display-referred frame */

/* In a create hook: the pass reads the atmosphere (its parameters and
 * LUTs, SB_BINDING_*) and the frame constants (SB_VIEW_BINDING_FRAME). */
void sb_pass_read_atmosphere(struct sb_renderer *r);
/* The resource the renderer or an earlier pass added under `name`, which
 * must be there. */
sb_resource sb_pass_find(struct sb_renderer *r, const char *name);

/* A host-visible storage buffer of `bytes`, filled from `data` unless NULL (then zeroed). */
enum sb_result sb_renderer_upload(struct sb_renderer *r, const void *data, size_t bytes, const char *name,
                                  struct sb_buffer *buffer);

/* A sampled RGBA16F texture of `image`'s values as halves (its channels,
 * then `fill`), 3D where the image has depth, else 2D; without an image
 * (NULL), one texel of `fill`, 3D when `volume`. */
enum sb_result sb_renderer_upload_image(struct sb_renderer *r, const struct sb_image *image, bool volume, float fill,
                                        const char *name, struct sb_texture *texture);

/* A compute pipeline on the pass's layout (its uses declared before). */
enum sb_result sb_renderer_kernel(struct sb_renderer *r, const uint32_t *spirv, size_t spirv_size, const char *name,
                                  VkPipeline *pipeline);

/* Record a dispatch of `pipeline` with the pass's first set (or set `set`)
 * covering width x height x depth invocations in groups of group_x x
 * group_y x group_z. */
void sb_renderer_dispatch(struct sb_renderer *r, VkPipeline pipeline, const struct sb_view_push *push,
                          const uint32_t size[3], const uint32_t group[3]);
void sb_renderer_dispatch_set(struct sb_renderer *r, uint32_t set, VkPipeline pipeline, const struct sb_view_push *push,
                              const uint32_t size[3], const uint32_t group[3]);
/* Bind a graphics pipeline, the pass's first set and `push`. */
void sb_renderer_bind_graphics(struct sb_renderer *r, VkPipeline pipeline, const struct sb_view_push *push);

/* Destroy what a pass made: its pipelines (VK_NULL_HANDLE ones skipped) and
 * textures (zeroed ones accepted). */
void sb_renderer_release(struct sb_renderer *r, const VkPipeline *pipelines, size_t pipeline_count,
                         struct sb_texture *const *textures, size_t texture_count);

/* A full memory barrier: every earlier command's writes before every later
 * command (between the steps of a pass). */
void sb_renderer_barrier(VkCommandBuffer cmd);

#endif
