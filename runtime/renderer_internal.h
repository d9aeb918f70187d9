/*
 * Inside skyview's renderer: the state its passes share, and the interface a
 * pass implements. A frame records the passes of sb_pass_classes in order;
 * adding a pass is a file that defines its class, an entry in enum sb_pass
 * (renderer.h) and one in that table (renderer.c).
 *
 * Every pass sees one descriptor set layout, the bindings of config.h's
 * SB_VIEW_BINDING_*: the renderer binds its own resources, and a pass binds
 * the ones it owns in its create hook (sb_renderer_bind_*), before the sets
 * are written. Every binding must be bound by then, so a pass that has
 * nothing to do in a frame still binds (small) resources.
 */
#ifndef SB_RUNTIME_RENDERER_INTERNAL_H
#define SB_RUNTIME_RENDERER_INTERNAL_H

#include "compute.h"
#include "config.h"
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
    bool post_in_place;          /* a pass after SB_PASS_LAST_LIT changes the HDR frame in place: each such
                                    pass sets it in its create hook when it will run */
    struct sb_buffer post_input; /* params.post_input as halves, or none */

    struct sb_texture sky_view, aerial, aerial_t, shadow, hdr, depth, bloom, ldr;
    VkSampler linear, nearest, shadow_compare, repeat; /* repeat: linear, wrapping (tileable noise) */

    /* What each binding of the sets points at (sb_renderer_bind_*). */
    const struct sb_buffer *bound_buffer[SB_VIEW_BINDING_COUNT];
    VkImageView bound_view[SB_VIEW_BINDING_COUNT];
    VkSampler bound_sampler[SB_VIEW_BINDING_COUNT]; /* NULL: the renderer's choice */

    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkDescriptorPool pool;
    VkDescriptorSet set;                       /* everything, bloom bindings at level 0 */
    VkDescriptorSet bloom_sets[SB_BLOOM_SETS]; /* down steps 0..L-1, then up steps */
    VkPipeline kernels[KERNEL_COUNT];
    VkPipeline shadow_pipeline, scene_pipeline;
    VkPipeline scene_volume_pipeline;          /* aerial perspective from its volume alone (aerial.glsl) */
    VkPipeline scene_trace[2];                 /* traced: generic, aerial perspective from its volume alone */
    struct sb_buffer bvh_nodes, bvh_triangles; /* the world's BVH when traced, else stand-ins */
    struct sb_texture depth_stand_in;          /* the depth output's binding when rasterised */

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
 * makes what the pass owns and binds it; `destroy` (may be NULL) frees it
 * and accepts a partly created pass; `record` adds the pass's commands to
 * r->cmd (its timestamps and the barrier after it are the renderer's). */
struct sb_pass_class {
    const char *name; /* in timing tables */
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

/* scene_trace.c: whether to trace the scene; the BVH and kernels (stand-ins
 * when not traced), bound; a frame's traced scene pass. */
bool sb_scene_trace_wanted(const struct sb_renderer_params *params, const struct sb_vk *vk, uint32_t vertex_count);
enum sb_result sb_scene_trace_create(struct sb_renderer *r, const struct sb_world *world);
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

/* Point a binding at a buffer, or at an image view with a sampler (NULL:
 * linear filtering clamped to the edge). They are kept by pointer or handle
 * and must outlive the renderer's sets. */
void sb_renderer_bind_buffer(struct sb_renderer *r, uint32_t binding, const struct sb_buffer *buffer);
void sb_renderer_bind_view(struct sb_renderer *r, uint32_t binding, VkImageView view, VkSampler sampler);

/* A host-visible storage buffer of `bytes`, filled from `data` unless NULL (then zeroed). */
enum sb_result sb_renderer_upload(struct sb_renderer *r, const void *data, size_t bytes, const char *name,
                                  struct sb_buffer *buffer);

/* A sampled RGBA16F texture of `image`'s values as halves (its channels,
 * then `fill`), 3D where the image has depth, else 2D; without an image
 * (NULL), one texel of `fill`, 3D when `volume`. */
enum sb_result sb_renderer_upload_image(struct sb_renderer *r, const struct sb_image *image, bool volume, float fill,
                                        const char *name, struct sb_texture *texture);

/* A compute pipeline on the renderer's layout. */
enum sb_result sb_renderer_kernel(struct sb_renderer *r, const uint32_t *spirv, size_t spirv_size, const char *name,
                                  VkPipeline *pipeline);

/* Record a dispatch of `pipeline` on the main set covering width x height x
 * depth invocations in groups of group_x x group_y x group_z. */
void sb_renderer_dispatch(struct sb_renderer *r, VkPipeline pipeline, const struct sb_view_push *push,
                          const uint32_t size[3], const uint32_t group[3]);

/* Record a copy of the whole of `src` into `dst` (same size and format),
 * both in the general layout before and after. */
void sb_renderer_copy_texture(struct sb_renderer *r, const struct sb_texture *src, const struct sb_texture *dst);

/* Destroy what a pass made: its pipelines (VK_NULL_HANDLE ones skipped) and
 * textures (zeroed ones accepted). */
void sb_renderer_release(struct sb_renderer *r, const VkPipeline *pipelines, size_t pipeline_count,
                         struct sb_texture *const *textures, size_t texture_count);

/* A full memory barrier: every earlier command's writes before every later command. */
void sb_renderer_barrier(VkCommandBuffer cmd);

#endif
