/*
 * Inside skyview's renderer: the state its passes share, the interface a
 * pass implements, and what a pass may call (pass.c). A frame records the
 * passes of sb_pass_classes in order; adding a pass is a file of passes/
 * that defines its class, an entry in enum sb_pass (renderer.h) and one in
 * that table (passes/passes.c).
 *
 * A pass's create hook makes what it owns, adds it to the render graph's
 * table of resources (graph.h), and declares what it uses of the table,
 * through which bindings (shaders/view/view_gpu.h and its own *_gpu.h); the graph gives
 * it its own descriptor set and the barriers before it.
 */
#ifndef SB_RUNTIME_RENDERER_INTERNAL_H
#define SB_RUNTIME_RENDERER_INTERNAL_H

#include "compute.h"
#include "config.h"
#include "graph.h"
#include "renderer.h"
#include "shadows.h"
#include "texels.h"
#include "texture.h"
#include "transform.h"
#include "view_gpu.h"

struct sb_image;

#define SB_HDR_FORMAT VK_FORMAT_R16G16B16A16_SFLOAT
#define SB_DEPTH_FORMAT VK_FORMAT_D32_SFLOAT
#define SB_NEAR_M 0.1         /* the view's near plane */
#define SB_AERIAL_FAR_KM 32.0 /* where the aerial-perspective volume ends */

struct sb_renderer {
    struct sb_vk *vk;
    struct sb_renderer_params params;
    const struct sb_pack *pack;   /* during sb_renderer_create only */
    const struct sb_world *world; /* likewise */
    uint32_t width, height, bloom_levels;
    uint32_t vertex_count, caster_first_vertex;
    struct sb_caster_box *caster_boxes; /* shadows.h */
    unsigned caster_box_count;
    int32_t cascade_clear[SB_CASCADES + 1][4]; /* this frame's texels to clear and draw in each cascade, then
                                                  in the far map (layer SB_CASCADES) */
    double radiance_scale;                     /* 1 / the sun's largest channel: radiance in units of the sun */
    double cd_m2_per_unit;                     /* the pack's radiance unit in cd/m^2 (params.sun_illuminance_lux) */
    double frame_scale;                        /* this frame's: what stored radiance is multiplied by, the
                                                  radiance scale times the pre-exposure (renderer.c) */
    double previous_frame_scale;               /* the last frame's, which its history was stored with */
    double next_frame_scale;                   /* the next frame's, from this frame's exposure */
    double readback_scale;                     /* the frame scale of the last frame read back */
    double ground_radius_km;
    float thickness_km;                    /* the atmosphere's, as the shaders hold it */
    bool camera_in_atmosphere;             /* this frame's: which sky kernel runs */
    uint32_t frame_lights;                 /* this frame's lights in the sky (sb_frame_gpu.lights.x) */
    double world_min_m[3], world_max_m[3]; /* the world's box */
    bool aerial_volume_only;               /* this frame's: which scene pipeline draws */
    bool scene_traced;                     /* the scene pass traces (passes/scene.c): no cascades to draw */
    bool world_bvh;                        /* the world's BVH is on the device: traced, or relighting */
    uint32_t probe_count;                  /* grid probes the probes pass lights (0: none), set by it */
    uint32_t reflection_count;             /* reflection cubes the scene reads (0: none), set by the
                                              reflections pass */

    /* The renderer's resources, in the graph's table under their names. */
    struct sb_buffer atmosphere; /* "atmosphere" */
    /* "transmittance", ...: RGBA32F, the LUT; the refined and lookup forms. The transmittance, the
     * ground's irradiance and the orders are 2D arrays: the scene's three channels in layer 0, and
     * with the spectral products, band b's three wavelengths in layer 1 + b (atmosphere.glsl) */
    struct sb_texture transmittance, multiscattering, irradiance_ground;
    struct sb_texture orders;                     /* "orders": the orders product as RGBA32F, or a 1 x 1 stand-in */
    struct sb_orders_push orders_grid;            /* its grid (zeros: the pack has none) */
    float spectral_rgb[3 * SB_SPECTRAL_BANDS][4]; /* the 12 wavelengths to Rec.709 (frame.glsl) */
    VkSpecializationInfo specialization;          /* every view kernel's (SB_VIEW_CONSTANT_*, pass.c) */
    VkSpecializationMapEntry specialization_entries[3];
    struct {
        VkBool32 orders;     /* the pack has the orders (SB_VIEW_CONSTANT_ORDERS) */
        VkBool32 bands;      /* and the spectral products: the sky at 12 wavelengths (SB_VIEW_CONSTANT_BANDS) */
        uint32_t band_lanes; /* SB_SPECTRAL_BANDS with them, else 1 (SB_VIEW_CONSTANT_BAND_LANES) */
    } constants;
    struct sb_buffer frame, vertices, exposure; /* "frame", "vertices", "exposure" */
    struct sb_buffer bvh_nodes, bvh_triangles;  /* "bvh nodes", "bvh triangles": the world's BVH when traced
                                                   or relighting reflections */
    struct sb_texel_set textures;               /* "texture records", "texels": the world's textures */
    struct sb_buffer instances;                 /* "instances": sb_instance_gpu[] (one zero when none) */
    struct sb_buffer emissive;                  /* "emissive": sb_emissive_gpu[] (one zero when none) */
    uint32_t emissive_count;                    /* the world's emitting materials */
    /* An instanced world's draws, a mesh each: its vertices in its own
     * space and its instances [first_instance, + instance_count). */
    struct sb_draw_group {
        uint32_t first_vertex, caster_first_vertex, end_vertex, first_instance, instance_count;
    } * draw_groups;
    uint32_t draw_group_count; /* 0: the world in place, drawn as one list */
    /* This frame's cull of an instanced world: each list (the frame, then
     * each cascade) holds, a group after another, the instances a draw
     * draws; "visible instances", written by the host before each submit. */
    struct sb_buffer visible;
    struct sb_visible_range {
        uint32_t first, count;      /* in the visible buffer */
    } * visible_ranges;             /* [(2 + SB_CASCADES) x draw_group_count]: the frame, each cascade, the far map */
    double (*instance_boxes)[2][3]; /* each instance's box in the world, and its casters' */
    double (*caster_instance_boxes)[2][3];
    struct sb_texture hdr, depth, ldr;                 /* "hdr", "depth", "ldr": the frame */
    VkSampler linear, nearest, shadow_compare, repeat; /* repeat: linear, wrapping (tileable noise) */

    struct sb_buffer read_ldr, read_hdr, read_sky_view, read_aerial;
    struct sb_buffer read_post;  /* the HDR frame after post-processing, when post_in_place */
    bool post_in_place;          /* a post-processing pass writes the HDR frame (from the graph) */
    int first_post;              /* the first post-processing pass: the lit frame is whole before it */
    struct sb_buffer post_input; /* params.post_input as halves, or none */

    struct sb_graph graph;          /* graph.h */
    int pass;                       /* the pass being created or recorded */
    const char *pass_name;          /* its name */
    void *pass_data[SB_PASS_COUNT]; /* what each pass keeps (sb_pass_data) */
    sb_resource hdr_id, ldr_id, sky_view_id, aerial_id;

    VkQueryPool queries;
    VkCommandBuffer cmd;
    VkFence fence;
    const struct sb_view *view; /* the frame being recorded */
    uint64_t frame_index;       /* frames rendered before this one */
    struct sb_mat4 view_proj;   /* of the last frame, camera-relative */
    double camera_m[3];
    double key_direction[3]; /* of the last frame: toward its key light (sb_frame_gpu.lights), world */
};

/* A pass: hooks called in sb_pass_classes' order, with r->pass its own
 * index. `create` (may be NULL) makes what the pass owns, adds it to the
 * graph's table and declares its uses (graph.h); `destroy` (may be NULL)
 * frees it and accepts a partly created pass; `record` adds the pass's
 * commands to r->cmd (its timestamps and the barriers before it are the
 * renderer's). */
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

/* A frame's passes, in order (passes/passes.c). */
extern const struct sb_pass_class *const sb_pass_classes[SB_PASS_COUNT];

/* Whether the pack's reflection_surfaces relight its cubes in this
 * renderer (passes/reflections.c): the probes pass then lights the sky's
 * SH, and the world's BVH is uploaded for the sun's shadows. */
bool sb_reflections_relightable(const struct sb_pack *pack, const struct sb_renderer_params *params,
                                const struct sb_world *world);

/* ---- What a pass calls (pass.c) ---- */

/* What the pass keeps between its hooks (NULL until set). */
void *sb_pass_data(struct sb_renderer *r);
void sb_pass_set_data(struct sb_renderer *r, void *data);

/* In a create hook: the pass reads the atmosphere (its parameters and
 * LUTs, SB_BINDING_*) and the frame constants (SB_VIEW_BINDING_FRAME). */
void sb_pass_read_atmosphere(struct sb_renderer *r);
/* The resource the renderer or an earlier pass added under `name`, which
 * must be there. */
sb_resource sb_pass_find(struct sb_renderer *r, const char *name);

/* A host-visible storage buffer of `bytes`, filled from `data` unless NULL (then zeroed). */
enum sb_result sb_renderer_upload(struct sb_renderer *r, const void *data, size_t bytes, const char *name,
                                  struct sb_buffer *buffer);

/* A texture of size[0] x size[1] x size[2] texels (depth 1: 2D), in the general layout. */
enum sb_result sb_renderer_texture(struct sb_renderer *r, struct sb_texture *t, const uint32_t size[3], uint32_t layers,
                                   uint32_t mips, VkFormat format, VkImageUsageFlags usage, const char *name);

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
 * group_y x group_z; over the whole frame in SB_WORKGROUP_X x Y groups. */
void sb_renderer_dispatch(struct sb_renderer *r, VkPipeline pipeline, const struct sb_view_push *push,
                          const uint32_t size[3], const uint32_t group[3]);
void sb_renderer_dispatch_set(struct sb_renderer *r, uint32_t set, VkPipeline pipeline, const struct sb_view_push *push,
                              const uint32_t size[3], const uint32_t group[3]);
void sb_renderer_dispatch_frame(struct sb_renderer *r, VkPipeline pipeline);
/* Bind a graphics pipeline, the pass's first set and `push`; set the
 * viewport and scissor to width x height. */
void sb_renderer_bind_graphics(struct sb_renderer *r, VkPipeline pipeline, const struct sb_view_push *push);
void sb_renderer_viewport(struct sb_renderer *r, uint32_t width, uint32_t height);

/* A pass that is one kernel over the frame: made after the pass's
 * declarations and kept as its data; its destroy and record hooks. A pass
 * that makes none (it has nothing to do) records nothing. */
enum sb_result sb_pass_frame_kernel(struct sb_renderer *r, const uint32_t *spirv, size_t spirv_size, const char *name);
void sb_pass_frame_kernel_destroy(struct sb_renderer *r);
void sb_pass_frame_kernel_record(struct sb_renderer *r);

/* Destroy a pass's textures (zeroed ones accepted). Its kernels, layouts
 * and pipelines are the context's (vulkan/pipeline.h): a pass never
 * destroys them. */
void sb_renderer_release(struct sb_renderer *r, struct sb_texture *const *textures, size_t texture_count);

/* A full memory barrier: every earlier command's writes before every later
 * command (between the steps of a pass; graph.c). */
void sb_renderer_barrier(VkCommandBuffer cmd);

/* atmosphere.c: the pack's atmosphere (which must hold transmittance,
 * multiscattering and irradiance_ground; SB_ERR_USAGE naming the missing
 * product otherwise) into r->atmosphere and its LUTs, r->radiance_scale
 * and the frame scales, r->ground_radius_km and r->thickness_km. */
enum sb_result sb_atmosphere_upload(struct sb_renderer *r, const struct sb_pack *pack);

/* passes/probes.c: in a create hook, the pass reads the probes
 * (probes.glsl's probe_lookup: "probes", "probe light", "probe detail"). */
void sb_pass_read_probes(struct sb_renderer *r);

/* world_gpu.c: the world's vertices, textures, emitting materials,
 * instances and their draws, and its BVH when r->world_bvh, into the
 * renderer's buffers ("vertices", ...), with its box and its casters'
 * boxes; released by sb_world_release (which accepts a partial upload).
 * sb_world_cull fills this frame's lists of visible instances (an
 * instanced world's; r->view_proj and r->camera_m set), the far map's
 * with `far` (NULL: none). */
struct sb_world;
enum sb_result sb_world_upload(struct sb_renderer *r, const struct sb_world *world);
void sb_world_release(struct sb_renderer *r);
void sb_world_cull(struct sb_renderer *r, const struct sb_cascades *cascades, const struct sb_mat4 *far);

/* grading.c: the scene-linear grading's GPU form; a .cube LUT (NULL: a
 * stand-in) as lut3d.glsl reads it, in a buffer of its own. */
struct sb_lut3d;
struct sb_grading_gpu;
void sb_grading_gpu_fill(const struct sb_grading *grading, struct sb_grading_gpu *gpu);
enum sb_result sb_grade_lut_upload(struct sb_renderer *r, const struct sb_lut3d *lut, struct sb_buffer *buffer);

#endif
