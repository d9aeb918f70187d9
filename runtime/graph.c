#include "graph.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "pipeline.h"
#include "renderer_internal.h"

#define PREVIOUS_BIT 0x80000000u

/* ---- The table ------------------------------------------------------------------- */

static sb_resource add(struct sb_renderer *r, const char *name)
{
    struct sb_graph *g = &r->graph;
    assert(!sb_graph_find(r, name) && "resource names are unique");
    if (g->resource_count + 1 >= SB_GRAPH_MAX_RESOURCES) {
        assert(!"SB_GRAPH_MAX_RESOURCES too small");
        return 0;
    }
    sb_resource id = ++g->resource_count;
    g->resources[id] = (struct sb_graph_resource){.name = name, .layout = VK_IMAGE_LAYOUT_GENERAL};
    return id;
}

sb_resource sb_graph_image(struct sb_renderer *r, const char *name, struct sb_texture *texture)
{
    sb_resource id = add(r, name);
    if (id)
        r->graph.resources[id].texture = texture; /* textures are made in the general layout */
    return id;
}

sb_resource sb_graph_history(struct sb_renderer *r, const char *name, struct sb_texture pair[2])
{
    assert(pair[0].format == pair[1].format && pair[0].width == pair[1].width && pair[0].depth == pair[1].depth);
    sb_resource id = sb_graph_image(r, name, &pair[0]);
    if (!id)
        return 0;
    struct sb_graph *g = &r->graph;
    sb_resource other = ++g->resource_count; /* nameless: found through the first */
    g->resources[other] = (struct sb_graph_resource){.texture = &pair[1], .layout = VK_IMAGE_LAYOUT_GENERAL};
    g->resources[id].pair = other;
    g->resources[other].pair = id;
    g->resources[id].current = true;
    return id;
}

sb_resource sb_graph_buffer(struct sb_renderer *r, const char *name, const struct sb_buffer *buffer)
{
    sb_resource id = add(r, name);
    if (id)
        r->graph.resources[id].buffer = buffer;
    return id;
}

sb_resource sb_graph_find(const struct sb_renderer *r, const char *name)
{
    const struct sb_graph *g = &r->graph;
    for (uint32_t i = 1; i <= g->resource_count; i++)
        if (g->resources[i].name && !strcmp(g->resources[i].name, name))
            return i;
    return 0;
}

/* The table's entry a resource names this frame: a history's current half, or its other with SB_PREVIOUS. */
static uint32_t entry(const struct sb_renderer *r, sb_resource resource)
{
    const struct sb_graph_resource *t = r->graph.resources;
    uint32_t i = resource & ~PREVIOUS_BIT;
    assert(i && i <= r->graph.resource_count);
    if (!t[i].pair) {
        assert(!(resource & PREVIOUS_BIT) && "only a history has a previous half");
        return i;
    }
    uint32_t current = t[i].current ? i : t[i].pair;
    return resource & PREVIOUS_BIT ? t[current].pair : current;
}

struct sb_texture *sb_graph_texture(struct sb_renderer *r, sb_resource resource)
{
    return r->graph.resources[entry(r, resource)].texture;
}

/* ---- Declarations ----------------------------------------------------------------- */

static struct sb_graph_pass *creating(struct sb_renderer *r)
{
    assert(r->pass >= 0 && r->pass < SB_PASS_COUNT);
    return &r->graph.passes[r->pass];
}

static void declare(struct sb_renderer *r, uint32_t binding, sb_resource resource, enum sb_use use, VkSampler sampler)
{
    struct sb_graph_pass *p = creating(r);
    assert(!p->layout && "uses are declared before the pass's pipelines");
    assert(resource && p->use_count < SB_GRAPH_MAX_USES);
    if (!resource || p->use_count >= SB_GRAPH_MAX_USES)
        return;
    for (uint32_t u = 0; u < p->use_count; u++)
        assert(binding == SB_NO_BINDING || p->uses[u].binding != binding);
    p->uses[p->use_count++] = (struct sb_graph_use){binding, resource, use, sampler};
    if (use == SB_USE_COLOR_TARGET || use == SB_USE_DEPTH_TARGET)
        p->graphics = true;
}

void sb_pass_use(struct sb_renderer *r, uint32_t binding, sb_resource resource, enum sb_use use)
{
    assert(use != SB_USE_SAMPLED || binding == SB_NO_BINDING);
    declare(r, binding, resource, use, VK_NULL_HANDLE);
}

void sb_pass_sample(struct sb_renderer *r, uint32_t binding, sb_resource resource, VkSampler sampler)
{
    declare(r, binding, resource, SB_USE_SAMPLED, sampler);
}

void sb_pass_sets(struct sb_renderer *r, uint32_t count)
{
    assert(count >= 1 && count <= SB_GRAPH_MAX_SETS && !creating(r)->layout);
    creating(r)->set_count = count;
}

void sb_pass_set_view(struct sb_renderer *r, uint32_t set, uint32_t binding, VkImageView view)
{
    struct sb_graph_pass *p = creating(r);
    assert(set < (p->set_count ? p->set_count : 1) && "sb_pass_sets first");
    uint32_t u = 0;
    while (u < p->use_count && p->uses[u].binding != binding)
        u++;
    assert(u < p->use_count && "a binding the pass declared");
    if (u < p->use_count && set < SB_GRAPH_MAX_SETS)
        p->set_views[set][u] = view;
}

static bool is_buffer(const struct sb_renderer *r, sb_resource resource)
{
    return r->graph.resources[resource & ~PREVIOUS_BIT].buffer != NULL;
}

static VkDescriptorType descriptor_type(const struct sb_renderer *r, const struct sb_graph_use *u)
{
    return u->use == SB_USE_SAMPLED    ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER
           : is_buffer(r, u->resource) ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER
                                       : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
}

enum sb_result sb_pass_layout(struct sb_renderer *r, VkPipelineLayout *out)
{
    enum sb_result res = SB_OK;
    struct sb_graph_pass *p = creating(r);
    if (!p->layout) {
        VkDescriptorSetLayoutBinding bindings[SB_GRAPH_MAX_USES];
        uint32_t n = 0;
        for (uint32_t u = 0; u < p->use_count; u++)
            if (p->uses[u].binding != SB_NO_BINDING)
                bindings[n++] = (VkDescriptorSetLayoutBinding){
                    .binding = p->uses[u].binding,
                    .descriptorType = descriptor_type(r, &p->uses[u]),
                    .descriptorCount = 1,
                    .stageFlags = VK_SHADER_STAGE_ALL,
                };
        if ((res = sb_vk_layout(r->vk, bindings, n, VK_SHADER_STAGE_ALL, sizeof(struct sb_view_push), &p->set_layout,
                                &p->layout)))
            goto cleanup;
        if (!p->set_count)
            p->set_count = 1;
    }
    *out = p->layout;
cleanup:
    return res;
}

/* ---- Sets ------------------------------------------------------------------------- */

/* Which half each of a pass's histories is this frame. */
static uint64_t parity(const struct sb_renderer *r, const struct sb_graph_pass *p)
{
    uint64_t key = 0;
    for (uint32_t u = 0; u < p->use_count; u++)
        key |= (uint64_t)(entry(r, p->uses[u].resource) & 1) << u;
    return key;
}

static void write_pass_sets(struct sb_renderer *r, struct sb_graph_pass *p)
{
    VkDescriptorBufferInfo buffers[SB_GRAPH_MAX_USES];
    VkDescriptorImageInfo images[SB_GRAPH_MAX_USES];
    VkWriteDescriptorSet writes[SB_GRAPH_MAX_USES];
    for (uint32_t s = 0; s < p->set_count; s++) {
        uint32_t n = 0;
        for (uint32_t u = 0; u < p->use_count; u++) {
            const struct sb_graph_use *use = &p->uses[u];
            if (use->binding == SB_NO_BINDING)
                continue;
            const struct sb_graph_resource *res = &r->graph.resources[entry(r, use->resource)];
            writes[n] = (VkWriteDescriptorSet){
                .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
                .dstSet = p->sets[s],
                .dstBinding = use->binding,
                .descriptorCount = 1,
                .descriptorType = descriptor_type(r, use),
            };
            if (res->buffer) {
                buffers[n] = (VkDescriptorBufferInfo){.buffer = res->buffer->buffer, .range = VK_WHOLE_SIZE};
                writes[n].pBufferInfo = &buffers[n];
            } else {
                bool depth = res->texture->aspect & VK_IMAGE_ASPECT_DEPTH_BIT;
                VkSampler sampler = use->sampler ? use->sampler : depth ? r->nearest : r->linear;
                images[n] = (VkDescriptorImageInfo){
                    .sampler = use->use == SB_USE_SAMPLED ? sampler : VK_NULL_HANDLE,
                    .imageView = p->set_views[s][u] ? p->set_views[s][u] : res->texture->view,
                    .imageLayout = depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL : VK_IMAGE_LAYOUT_GENERAL,
                };
                writes[n].pImageInfo = &images[n];
            }
            n++;
        }
        vkUpdateDescriptorSets(r->vk->device, n, writes, 0, NULL);
    }
    p->sets_parity = parity(r, p);
}

enum sb_result sb_graph_write_sets(struct sb_renderer *r)
{
    enum sb_result res = SB_OK;
    struct sb_graph *g = &r->graph;
    uint32_t counts[3] = {0}, set_count = 0; /* storage buffers, sampled, storage images */
    for (int i = 0; i < SB_PASS_COUNT; i++) {
        const struct sb_graph_pass *p = &g->passes[i];
        for (uint32_t u = 0; p->layout && u < p->use_count; u++) {
            if (p->uses[u].binding == SB_NO_BINDING)
                continue;
            VkDescriptorType type = descriptor_type(r, &p->uses[u]);
            counts[type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER  ? 0
                   : type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE ? 2
                                                              : 1] += p->set_count;
        }
        set_count += p->layout ? p->set_count : 0;
    }
    if (!set_count)
        return SB_OK;
    const VkDescriptorType types[3] = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                       VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
    VkDescriptorPoolSize sizes[3];
    uint32_t n = 0;
    for (int i = 0; i < 3; i++)
        if (counts[i])
            sizes[n++] = (VkDescriptorPoolSize){.type = types[i], .descriptorCount = counts[i]};
    VkDescriptorPoolCreateInfo pool_info = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
        .maxSets = set_count,
        .poolSizeCount = n,
        .pPoolSizes = sizes,
    };
    VK(vkCreateDescriptorPool(r->vk->device, &pool_info, NULL, &g->pool));
    for (int i = 0; i < SB_PASS_COUNT; i++) {
        struct sb_graph_pass *p = &g->passes[i];
        if (!p->layout)
            continue;
        VkDescriptorSetLayout layouts[SB_GRAPH_MAX_SETS];
        for (uint32_t s = 0; s < p->set_count; s++)
            layouts[s] = p->set_layout;
        VkDescriptorSetAllocateInfo alloc = {
            .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
            .descriptorPool = g->pool,
            .descriptorSetCount = p->set_count,
            .pSetLayouts = layouts,
        };
        VK(vkAllocateDescriptorSets(r->vk->device, &alloc, p->sets));
        write_pass_sets(r, p);
    }
cleanup:
    return res;
}

void sb_graph_destroy(struct sb_renderer *r)
{
    struct sb_graph *g = &r->graph;
    VkDevice d = r->vk->device;
    if (g->pool)
        vkDestroyDescriptorPool(d, g->pool, NULL);
    free(g->passes); /* the passes' layouts are the context's */
    memset(g, 0, sizeof(*g));
}

/* ---- Barriers --------------------------------------------------------------------- */

void sb_renderer_barrier(VkCommandBuffer cmd)
{
    VkMemoryBarrier b = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT,
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &b, 0, NULL,
                         0, NULL);
}

struct access {
    VkPipelineStageFlags stages;
    VkAccessFlags read, write;
    VkImageLayout layout;
    bool discard; /* the old contents are not needed */
};

static struct access access_of(const struct sb_graph_resource *res, enum sb_use use, bool graphics)
{
    const VkPipelineStageFlags shaders =
        graphics ? VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT
                 : VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    bool depth = res->texture && res->texture->aspect & VK_IMAGE_ASPECT_DEPTH_BIT;
    struct access a = {.stages = shaders, .layout = VK_IMAGE_LAYOUT_GENERAL};
    switch (use) {
    case SB_USE_SAMPLED:
        a.read = VK_ACCESS_SHADER_READ_BIT;
        if (depth)
            a.layout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
        break;
    case SB_USE_LOAD:
        a.read = VK_ACCESS_SHADER_READ_BIT;
        break;
    case SB_USE_STORE:
        a.write = VK_ACCESS_SHADER_WRITE_BIT;
        break;
    case SB_USE_LOAD_STORE:
        a.read = VK_ACCESS_SHADER_READ_BIT;
        a.write = VK_ACCESS_SHADER_WRITE_BIT;
        break;
    case SB_USE_OVERWRITE:
        a.write = VK_ACCESS_SHADER_WRITE_BIT;
        a.discard = true;
        break;
    case SB_USE_COLOR_TARGET:
        a.stages = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
        a.write = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
        a.layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        a.discard = true;
        break;
    case SB_USE_DEPTH_TARGET:
        /* Drawn in the attachment-optimal layout and read in the read-only
         * one: a general layout costs NVIDIA its depth compression (the
         * H200 drew the cascades in 2.46 ms from the general layout, 1.30
         * ms from this one). */
        a.stages = VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
        a.read = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT;
        a.write = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
        a.layout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        a.discard = true;
        break;
    case SB_USE_COPY_SRC:
        a.stages = VK_PIPELINE_STAGE_TRANSFER_BIT;
        a.read = VK_ACCESS_TRANSFER_READ_BIT;
        a.layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        break;
    case SB_USE_COPY_DST:
        a.stages = VK_PIPELINE_STAGE_TRANSFER_BIT;
        a.write = VK_ACCESS_TRANSFER_WRITE_BIT;
        a.layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        a.discard = true; /* the renderer copies whole images */
        break;
    }
    return a;
}

/* One barrier command gathering a pass's dependencies. */
struct barrier {
    VkPipelineStageFlags src, dst;
    VkMemoryBarrier memory;
    VkImageMemoryBarrier images[SB_GRAPH_MAX_USES];
    uint32_t image_count;
};

/* Add to `b` what an access of entry `i` of the table needs after the
 * accesses before it this frame, and account for it. */
static void depend(struct sb_renderer *r, uint32_t i, const struct access *a, struct barrier *b)
{
    struct sb_graph_resource *res = &r->graph.resources[i];
    bool transition = res->texture && (a->discard || res->layout != a->layout);
    VkPipelineStageFlags src = 0;
    VkAccessFlags src_access = 0;
    if (a->write || transition) { /* after every earlier access */
        src = res->write_stages | res->read_stages;
        src_access = res->write_access;
    } else if (res->write_stages && (res->visible_stages & a->stages) != a->stages) { /* after the last write */
        src = res->write_stages;
        src_access = res->write_access;
    }
    if (transition) {
        assert(b->image_count < SB_GRAPH_MAX_USES);
        b->images[b->image_count++] = (VkImageMemoryBarrier){
            .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
            .srcAccessMask = src_access,
            .dstAccessMask = a->read | a->write,
            .oldLayout = a->discard ? VK_IMAGE_LAYOUT_UNDEFINED : res->layout,
            .newLayout = a->layout,
            .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
            .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
            .image = res->texture->image,
            .subresourceRange = {res->texture->aspect, 0, res->texture->mips, 0, res->texture->layers},
        };
        b->src |= src ? src : VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT;
        b->dst |= a->stages;
        res->layout = a->layout;
    } else if (src) {
        b->memory.srcAccessMask |= src_access;
        b->memory.dstAccessMask |= a->read | a->write;
        b->src |= src;
        b->dst |= a->stages;
    }
    if (a->write) {
        res->write_stages = a->stages;
        res->write_access = a->write;
        res->read_stages = res->visible_stages = 0;
        res->written = true;
    } else if (transition) { /* the transition is a write the next accesses come after */
        res->write_stages = res->read_stages = res->visible_stages = a->stages;
        res->write_access = 0;
    } else {
        res->read_stages |= a->stages;
        if (src)
            res->visible_stages |= a->stages;
    }
}

static void flush(struct sb_renderer *r, struct barrier *b)
{
    if (!b->src)
        return;
    b->memory.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    bool memory = b->memory.srcAccessMask || b->memory.dstAccessMask;
    vkCmdPipelineBarrier(r->cmd, b->src, b->dst, 0, memory, &b->memory, 0, NULL, b->image_count, b->images);
}

void sb_graph_before_pass(struct sb_renderer *r, int pass)
{
    const struct sb_graph_pass *p = &r->graph.passes[pass];
    struct barrier b = {0};
    /* Each entry once, its uses' accesses merged (a pass may sample what it
     * also stores to, in one layout). */
    uint32_t done[SB_GRAPH_MAX_USES], done_count = 0;
    for (uint32_t u = 0; u < p->use_count; u++) {
        uint32_t i = entry(r, p->uses[u].resource), k = 0;
        while (k < done_count && done[k] != i)
            k++;
        if (k < done_count)
            continue;
        done[done_count++] = i;
        struct access a = access_of(&r->graph.resources[i], p->uses[u].use, p->graphics);
        for (uint32_t v = u + 1; v < p->use_count; v++) {
            if (entry(r, p->uses[v].resource) != i)
                continue;
            struct access more = access_of(&r->graph.resources[i], p->uses[v].use, p->graphics);
            assert(more.layout == a.layout && "one layout a pass");
            a.stages |= more.stages;
            a.read |= more.read;
            a.write |= more.write;
            a.discard &= more.discard;
        }
        depend(r, i, &a, &b);
    }
    flush(r, &b);
}

void sb_graph_access(struct sb_renderer *r, sb_resource resource, enum sb_use use)
{
    uint32_t i = entry(r, resource);
    struct access a = access_of(&r->graph.resources[i], use, false);
    struct barrier b = {0};
    depend(r, i, &a, &b);
    flush(r, &b);
}

void sb_graph_begin_frame(struct sb_renderer *r)
{
    struct sb_graph *g = &r->graph;
    /* The sets of passes whose histories swapped (none is in use: the last
     * frame is done). */
    for (int i = 0; i < SB_PASS_COUNT; i++) {
        struct sb_graph_pass *p = &g->passes[i];
        if (p->layout && p->sets_parity != parity(r, p))
            write_pass_sets(r, p);
    }
    /* The last frame's commands are done (the renderer waits for them);
     * one full barrier orders this frame's after them, so the table starts
     * with nothing pending. */
    sb_renderer_barrier(r->cmd);
    for (uint32_t i = 1; i <= g->resource_count; i++) {
        struct sb_graph_resource *res = &g->resources[i];
        res->write_stages = res->read_stages = res->visible_stages = 0;
        res->write_access = 0;
        res->written = false;
    }
}

void sb_graph_end_frame(struct sb_renderer *r)
{
    struct sb_graph *g = &r->graph;
    for (uint32_t i = 1; i <= g->resource_count; i++) {
        struct sb_graph_resource *res = &g->resources[i];
        if (res->pair && res->current && res->written) { /* this frame's is the next frame's previous */
            res->current = false;
            g->resources[res->pair].current = true;
        }
    }
}
