/*
 * skyview's render graph, sized for what it runs: one queue, passes in a
 * fixed order (enum sb_pass), no aliasing, culling or reordering.
 *
 * Resources (images and buffers) are entries of a table, found by name. A
 * pass declares in its create hook each resource it uses, how (enum
 * sb_use), and through which of its shaders' bindings; from that the graph
 * makes the pass's own descriptor set layout, pipeline layout and sets
 * (the bindings it declares, and no others), and, as a frame is recorded,
 * the barriers and image layouts before each pass. A history is a declared
 * pair of images: a pass writes the current one and reads the previous
 * one (SB_PREVIOUS), and the two swap after every frame that writes it.
 *
 * The graph orders passes against each other; a pass of several steps
 * (dispatches that read what the one before wrote) puts barriers between
 * its own steps (sb_renderer_barrier).
 */
#ifndef SB_RUNTIME_GRAPH_H
#define SB_RUNTIME_GRAPH_H

#include <stdbool.h>
#include <stdint.h>

#include "compute.h"
#include "texture.h"

#define SB_GRAPH_MAX_RESOURCES 96
#define SB_GRAPH_MAX_USES 32 /* a pass's */
#define SB_GRAPH_MAX_SETS 16 /* a pass's (bloom: a set a step) */

/* A resource: an index into the table, 0 for none. The previous half of a
 * history: SB_PREVIOUS(resource). */
typedef uint32_t sb_resource;
#define SB_PREVIOUS(resource) ((resource) | 0x80000000u)
#define SB_NO_BINDING UINT32_MAX /* a use through no binding (attachments) */

enum sb_use {
    SB_USE_SAMPLED,      /* read through a sampler (COMBINED_IMAGE_SAMPLER) */
    SB_USE_LOAD,         /* read: a storage image or buffer */
    SB_USE_STORE,        /* written, perhaps in part: a storage image or buffer */
    SB_USE_LOAD_STORE,   /* read and written */
    SB_USE_OVERWRITE,    /* a storage image written whole: its old contents are dropped */
    SB_USE_COLOR_TARGET, /* a colour attachment, cleared and drawn */
    SB_USE_DEPTH_TARGET, /* a depth attachment, cleared and drawn */
    SB_USE_COPY_SRC,     /* read by a copy (the renderer's readback) */
    SB_USE_COPY_DST,     /* written by a copy */
};

struct sb_graph_resource {
    const char *name;
    struct sb_texture *texture; /* or NULL */
    const struct sb_buffer *buffer;
    uint32_t pair; /* a history's other half (0: none) */
    bool current;  /* of a history: the half written this frame */
    bool written;  /* this frame */
    /* Where it stands as the frame is recorded. */
    VkImageLayout layout;
    VkPipelineStageFlags write_stages, read_stages, visible_stages;
    VkAccessFlags write_access;
};

struct sb_graph_use {
    uint32_t binding;
    sb_resource resource;
    enum sb_use use;
    VkSampler sampler; /* sampled */
};

struct sb_graph_pass {
    struct sb_graph_use uses[SB_GRAPH_MAX_USES];
    uint32_t use_count;
    uint32_t set_count; /* 0 until the layout is made; then 1 unless sb_pass_sets */
    VkImageView set_views[SB_GRAPH_MAX_SETS][SB_GRAPH_MAX_USES]; /* per set, per use: NULL: the resource's */
    bool graphics; /* it declared an attachment: its bindings are read by vertex and fragment shaders */
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkDescriptorSet sets[SB_GRAPH_MAX_SETS];
    uint64_t sets_parity; /* its histories' halves when its sets were written */
};

struct sb_graph {
    struct sb_graph_resource resources[SB_GRAPH_MAX_RESOURCES]; /* [0] unused */
    uint32_t resource_count;
    struct sb_graph_pass *passes; /* SB_PASS_COUNT */
    VkDescriptorPool pool;
};

struct sb_renderer;

/* Add a resource to the table (names are unique; `texture` and `buffer`
 * must outlive the renderer's sets). A history's two halves must match. */
sb_resource sb_graph_image(struct sb_renderer *r, const char *name, struct sb_texture *texture);
sb_resource sb_graph_history(struct sb_renderer *r, const char *name, struct sb_texture pair[2]);
sb_resource sb_graph_buffer(struct sb_renderer *r, const char *name, const struct sb_buffer *buffer);
/* The resource of that name, or 0. */
sb_resource sb_graph_find(const struct sb_renderer *r, const char *name);

/*
 * In a pass's create hook: it uses `resource` as `use` through `binding` of
 * its shaders' set (SB_NO_BINDING for an attachment); a sampled image
 * through `sampler` (NULL: linear, or nearest for a depth format). Declare
 * every use before creating the pass's pipelines (sb_renderer_kernel, the
 * layout): they fix the layout.
 */
void sb_pass_use(struct sb_renderer *r, uint32_t binding, sb_resource resource, enum sb_use use);
void sb_pass_sample(struct sb_renderer *r, uint32_t binding, sb_resource resource, VkSampler sampler);
/* A pass with `count` sets of one layout (bloom: a set a step), each like
 * the first except where sb_pass_set_view points a binding of set `set` at
 * another view of its resource (a mip level). */
void sb_pass_sets(struct sb_renderer *r, uint32_t count);
void sb_pass_set_view(struct sb_renderer *r, uint32_t set, uint32_t binding, VkImageView view);
/* The pass's pipeline layout, made from its uses on the first call. */
enum sb_result sb_pass_layout(struct sb_renderer *r, VkPipelineLayout *layout);

/* The renderer's side: the sets of every pass, once all are created; a
 * frame's start (the last frame's work is done) and its end (histories
 * swap); the barriers before pass `pass` records; a resource accessed
 * outside the passes (a copy); everything the graph made. */
enum sb_result sb_graph_write_sets(struct sb_renderer *r);
void sb_graph_begin_frame(struct sb_renderer *r);
void sb_graph_end_frame(struct sb_renderer *r);
void sb_graph_before_pass(struct sb_renderer *r, int pass);
void sb_graph_access(struct sb_renderer *r, sb_resource resource, enum sb_use use);
void sb_graph_destroy(struct sb_renderer *r);

/* The image of a resource this frame (the current half of a history,
 * or with SB_PREVIOUS the other). */
struct sb_texture *sb_graph_texture(struct sb_renderer *r, sb_resource resource);

#endif
