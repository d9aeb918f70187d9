/*
 * The reflection probes: the pack's cubes uploaded ("reflections" and
 * "reflection cubes" in the graph's table, which the scene reads) and,
 * where the pack holds reflection_surfaces, relit for this frame's lights
 * (docs/reflections.md, "Relighting"): a cube's level 0 from its surfaces
 * (reflection_relight.comp: the sky through the sky-view LUT, surfaces by
 * the sun and the moon through the transmittance LUT with a shadow ray
 * through the world's BVH, and the sky through each texel's transfer),
 * its box chain (reflection_chain.comp), then every level's GGX prefilter
 * as the bake's (reflection_filter.comp), over the cube's chain.
 *
 * A cube is relit when the lights have moved since it was lit (the baked
 * cubes stand for the sun they were captured under): every stale cube in a
 * frame that snaps (sb_view.snap_exposure: a still, a first frame), else
 * at most sb_renderer_params.relight_cubes a frame (2 by default), taking
 * turns, so a day's sweep costs a few cubes a frame.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "image.h"
#include "log.h"
#include "physics.h"
#include "probes_gpu.h"
#include "reflections_gpu.h"
#include "renderer_internal.h"
#include "sh.h"
#include "transform.h"

#include "reflection_chain.spv.h"
#include "reflection_filter.spv.h"
#include "reflection_relight.spv.h"
#include "reflection_relight_instanced.spv.h"

/* Cubes relit in a frame that does not snap, unless the params say. */
#define SB_RELIGHT_PER_FRAME 2
/* The samples a relit level 1 texel takes (doubling per level, as the
 * bake's `samples`; docs/reflections.md measures it against the bake). */
#define SB_RELIGHT_SAMPLES 64

struct lights {
    double sun[3], moon[3];
    uint32_t count; /* lights in the sky (the frame's) */
};

struct reflections {
    struct sb_buffer reflections, cubes; /* sb_reflections_gpu, its probes and the DFG; the cubes */
    struct sb_buffer surfaces, chain, relight;
    uint32_t count, levels, face_size;
    uint64_t chain_texels; /* a cube's, every level */
    double baked_sun[3];   /* the sun the cubes were captured under */
    bool relit;            /* the pack's surfaces relight the cubes */
    struct lights *lit;    /* what each cube is lit for */
    uint32_t next;         /* the cube the turns start from */
    VkPipeline relight_kernel, chain_kernel, filter_kernel;
};

/*
 * The pack's reflection probes (reflections.glsl), or none: the cubes
 * reordered from the pack's level-major image to one chain a cube, the
 * probes' positions and boxes, and the DFG LUT when the pack has it (else
 * the shader's analytic fit). The sky-only cube's irradiance on an upward
 * surface, for a scaled cube under another sun where nothing relights it.
 */
static enum sb_result upload_reflections(struct sb_renderer *r, struct reflections *s)
{
    const struct sb_pack *pack = r->pack;
    const struct sb_image *cubes = &pack->images[SB_PRODUCT_REFLECTION_CUBES];
    const struct sb_image *records = &pack->images[SB_PRODUCT_REFLECTION_PROBES];
    bool use = pack->present[SB_PRODUCT_REFLECTION_CUBES] && pack->present[SB_PRODUCT_REFLECTION_PROBES] &&
               !r->params.no_reflections && records->width == cubes->depth &&
               cubes->levels < SB_RELIGHT_MAX_LEVELS; /* [3].w: the chain */
    bool dfg = use && pack->present[SB_PRODUCT_DFG];
    uint32_t count = use ? cubes->depth : 0, n = use ? cubes->width : 1, levels = use ? cubes->levels : 1;
    uint64_t chain = 0, level_offsets[SB_RELIGHT_MAX_LEVELS];
    for (uint32_t l = 0; l < levels; l++) {
        level_offsets[l] = chain;
        chain += 6ull * sb_image_level_size(n, l) * sb_image_level_size(n, l);
    }
    size_t header_vec4s = (sizeof(struct sb_reflections_gpu) + 15) / 16;
    size_t vec4s = header_vec4s + 3 * (size_t)count + (dfg ? (size_t)SB_DFG_SIZE * SB_DFG_SIZE : 0);
    enum sb_result res = sb_renderer_upload(r, NULL, vec4s * 16, "reflection probes", &s->reflections);
    if (!res)
        res = sb_renderer_upload(r, NULL, (use ? chain * count : 1) * 16, "reflection cubes", &s->cubes);
    if (res || !use)
        return res;
    struct sb_reflections_gpu *g = s->reflections.mapped;
    g->info[0] = n;
    g->info[1] = levels;
    g->info[2] = count;
    s->count = r->reflection_count = count;
    s->levels = levels;
    s->face_size = n;
    s->chain_texels = chain;
    g->info[3] = dfg;
    sb_direction(pack->scene->view.sun_azimuth_deg * M_PI / 180, pack->scene->view.sun_elevation_deg * M_PI / 180,
                 s->baked_sun);
    for (int k = 0; k < 3; k++)
        g->baked_sun[k] = (float)s->baked_sun[k];
    /* The sky-only cube's irradiance SH (its record's channels 9 on, k then rgb) at +y. */
    const double up[3] = {0, 1, 0};
    for (int c = 0; c < 3; c++) {
        double coefficients[SB_PROBE_SH];
        for (int k = 0; k < SB_PROBE_SH; k++)
            coefficients[k] = records->data[9 + 3 * k + c];
        g->baked_sky_up[c] = (float)sb_sh9_eval(coefficients, up);
    }
    for (uint32_t l = 0; l < levels; l++)
        g->level_offsets[l / 4][l % 4] = (uint32_t)level_offsets[l];
    g->level_offsets[3][3] = (uint32_t)chain;
    float *data = (float *)s->reflections.mapped + 4 * header_vec4s;
    for (uint32_t i = 0; i < count; i++)
        for (int k = 0; k < 9; k++) /* position, box min, box max: the record's first nine channels */
            data[12 * i + 4 * (k / 3) + k % 3] = records->data[(size_t)i * records->channel_count + k];
    if (dfg) {
        const struct sb_image *lut = &pack->images[SB_PRODUCT_DFG];
        float *d = data + 12 * (size_t)count;
        for (size_t t = 0; t < (size_t)SB_DFG_SIZE * SB_DFG_SIZE; t++) {
            d[4 * t] = lut->data[2 * t];
            d[4 * t + 1] = lut->data[2 * t + 1];
        }
    }
    float *texels = s->cubes.mapped;
    for (uint32_t l = 0; l < levels; l++) {
        uint32_t m = sb_image_level_size(n, l);
        const float *src = cubes->data + sb_image_level_offset(cubes, l);
        for (uint32_t i = 0; i < count; i++)
            for (size_t t = 0; t < 6ull * m * m; t++) {
                float *o = texels + 4 * (i * chain + g->level_offsets[l / 4][l % 4] + t);
                memcpy(o, src + 3 * ((size_t)i * 6 * m * m + t), 3 * sizeof(float));
            }
    }
    sb_info("reflections: %u cubes of %u^2, %u levels%s", count, n, levels, dfg ? ", the DFG LUT" : "");
    return SB_OK;
}

/* Whether the pack's surfaces relight its cubes: the cubes' shape, and a
 * world to trace the sun's shadows through. */
bool sb_reflections_relightable(const struct sb_pack *pack, const struct sb_renderer_params *params,
                                const struct sb_world *world)
{
    const struct sb_image *cubes = &pack->images[SB_PRODUCT_REFLECTION_CUBES];
    const struct sb_image *surfaces = &pack->images[SB_PRODUCT_REFLECTION_SURFACES];
    return pack->present[SB_PRODUCT_REFLECTION_SURFACES] && pack->present[SB_PRODUCT_REFLECTION_CUBES] &&
           !params->no_reflections && !params->baked_reflections && surfaces->width == cubes->width &&
           surfaces->depth == cubes->depth && surfaces->channel_count == 4 * SB_RELIGHT_VEC4S &&
           world->vertex_count >= 3;
}

/* The pack's surfaces, level 0 of each cube, and the chain and the
 * prefilter's layout a relight uses. */
static enum sb_result upload_relight(struct sb_renderer *r, struct reflections *s)
{
    const struct sb_image *surfaces = &r->pack->images[SB_PRODUCT_REFLECTION_SURFACES];
    size_t texels = 6ull * s->face_size * s->face_size;
    enum sb_result res = sb_renderer_upload(r, NULL, (s->relit ? texels * s->count * SB_RELIGHT_VEC4S : 1) * 16,
                                            "reflection surfaces", &s->surfaces);
    if (!res)
        res = sb_renderer_upload(r, NULL, (s->relit ? s->chain_texels : 1) * 16, "reflection chain", &s->chain);
    if (!res)
        res = sb_renderer_upload(r, NULL, sizeof(struct sb_relight_gpu), "relight", &s->relight);
    if (res || !s->relit)
        return res;
    /* level 0 of each cube; the GPU's vec4s are the channels in order (config.h) */
    for (uint32_t i = 0; i < s->count; i++)
        memcpy((float *)s->surfaces.mapped + i * texels * 4 * SB_RELIGHT_VEC4S,
               surfaces->data + (size_t)i * texels * surfaces->channel_count,
               texels * surfaces->channel_count * sizeof(float));
    struct sb_relight_gpu *g = s->relight.mapped;
    for (uint32_t l = 1; l < s->levels; l++) {
        uint32_t m = s->face_size >> l, groups[2], tpt;
        uint32_t samples = sb_reflection_level_samples(SB_RELIGHT_SAMPLES, l);
        sb_prefilter_layout(samples, 6ull * m * m, SB_PREFILTER_THREADS, &tpt, groups);
        float roughness = (float)sb_reflection_level_roughness(l, s->levels);
        g->level[l][0] = samples;
        g->level[l][1] = tpt;
        g->level[l][2] = groups[0];
        memcpy(&g->level[l][3], &roughness, sizeof(float));
    }
    s->lit = calloc(s->count, sizeof(*s->lit));
    if (!s->lit)
        return SB_ERR_NOMEM;
    for (uint32_t i = 0; i < s->count; i++) { /* as baked: the scene's sun alone */
        memcpy(s->lit[i].sun, s->baked_sun, sizeof(s->baked_sun));
        s->lit[i].count = 1;
    }
    ((struct sb_reflections_gpu *)s->reflections.mapped)->baked_sun[3] = 1.0f;
    sb_info("reflections: relit for each sun from the pack's surfaces (%u GGX samples at mip 1)", SB_RELIGHT_SAMPLES);
    return SB_OK;
}

static enum sb_result reflections_create(struct sb_renderer *r)
{
    struct reflections *s = calloc(1, sizeof(*s));
    if (!s)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, s);
    enum sb_result res = upload_reflections(r, s);
    s->relit = !res && s->count && sb_reflections_relightable(r->pack, &r->params, r->world);
    if (!res && s->count && !s->relit && r->pack->present[SB_PRODUCT_REFLECTION_SURFACES] &&
        !r->params.baked_reflections)
        sb_warn("the pack's reflection_surfaces do not fit its reflection_cubes or the world has no triangles to "
                "shadow: the cubes as baked, scaled under another sun");
    if (!res)
        res = upload_relight(r, s);
    if (res)
        return res;
    sb_resource reflections = sb_graph_buffer(r, "reflections", &s->reflections);
    sb_resource cubes = sb_graph_buffer(r, "reflection cubes", &s->cubes);
    if (!s->relit)
        return SB_OK;
    sb_pass_read_atmosphere(r);
    sb_pass_sample(r, SB_VIEW_BINDING_SKY_VIEW, sb_pass_find(r, "sky-view"), NULL);
    sb_pass_use(r, SB_VIEW_BINDING_PROBE_LIGHT, sb_pass_find(r, "probe light"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_BVH_NODES, sb_pass_find(r, "bvh nodes"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_BVH_TRIANGLES, sb_pass_find(r, "bvh triangles"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_REFLECTIONS, reflections, SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_REFLECTION_CUBES, cubes, SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_REFLECTION_SURFACES, sb_graph_buffer(r, "reflection surfaces", &s->surfaces),
                SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_REFLECTION_CHAIN, sb_graph_buffer(r, "reflection chain", &s->chain),
                SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_RELIGHT, sb_graph_buffer(r, "relight", &s->relight), SB_USE_LOAD);
    if (r->draw_group_count)
        res = sb_renderer_kernel(r, sb_spv_reflection_relight_instanced, sizeof(sb_spv_reflection_relight_instanced),
                                 "reflection relight (instances)", &s->relight_kernel);
    else
        res = sb_renderer_kernel(r, sb_spv_reflection_relight, sizeof(sb_spv_reflection_relight), "reflection relight",
                                 &s->relight_kernel);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_reflection_chain, sizeof(sb_spv_reflection_chain), "reflection chain",
                                 &s->chain_kernel);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_reflection_filter, sizeof(sb_spv_reflection_filter), "reflection filter",
                                 &s->filter_kernel);
    return res;
}

static void reflections_destroy(struct sb_renderer *r)
{
    struct reflections *s = sb_pass_data(r);
    if (!s)
        return;
    struct sb_buffer *buffers[] = {&s->reflections, &s->cubes, &s->surfaces, &s->chain, &s->relight};
    for (size_t i = 0; i < sizeof(buffers) / sizeof(buffers[0]); i++)
        sb_buffer_destroy(r->vk, buffers[i]);
    free(s->lit);
    free(s);
}

/* This frame's lights: the sun, and the moon when it lights the sky. */
static struct lights frame_lights(const struct sb_renderer *r)
{
    const struct sb_view *v = r->view;
    struct lights now = {.count = r->frame_lights};
    sb_direction(v->sun_azimuth, v->sun_elevation, now.sun);
    if (v->moon && now.count > 1)
        sb_direction(v->moon_azimuth, v->moon_elevation, now.moon);
    return now;
}

/* Whether a cube lit for `then` is stale now: a light moved by more than
 * 2e-4 rad (0.01 degree) or the lights in the sky changed. */
static bool stale(const struct lights *then, const struct lights *now)
{
    double most = 0.0;
    for (int k = 0; k < 3; k++)
        most = fmax(most, fmax(fabs(then->sun[k] - now->sun[k]), fabs(then->moon[k] - now->moon[k])));
    return most > 2e-4 || then->count != now->count;
}

static void relight(struct sb_renderer *r, struct reflections *s, uint32_t cube)
{
    uint32_t n = s->face_size;
    const uint32_t group[3] = {SB_RELIGHT_THREADS, 1, 1};
    struct sb_view_push push = {.item = cube};
    sb_renderer_dispatch(r, s->relight_kernel, &push, (const uint32_t[3]){6 * n * n, 1, 1}, group);
    for (uint32_t l = 1; l < s->levels; l++) {
        uint32_t m = n >> l;
        sb_renderer_barrier(r->cmd);
        push.level = l;
        sb_renderer_dispatch(r, s->chain_kernel, &push, (const uint32_t[3]){6 * m * m, 1, 1}, group);
    }
    sb_renderer_barrier(r->cmd);
    const struct sb_relight_gpu *g = s->relight.mapped;
    for (uint32_t l = 1; l < s->levels; l++) {
        uint32_t m = n >> l, groups[2], tpt;
        sb_prefilter_layout(g->level[l][0], 6ull * m * m, SB_PREFILTER_THREADS, &tpt, groups);
        push.level = l;
        sb_renderer_dispatch(r, s->filter_kernel, &push,
                             (const uint32_t[3]){groups[0] * SB_PREFILTER_THREADS, groups[1], 1},
                             (const uint32_t[3]){SB_PREFILTER_THREADS, 1, 1});
    }
}

static void reflections_record(struct sb_renderer *r)
{
    struct reflections *s = sb_pass_data(r);
    if (!s->relit)
        return;
    struct lights now = frame_lights(r);
    uint32_t per_frame = r->params.relight_cubes ? r->params.relight_cubes : SB_RELIGHT_PER_FRAME;
    uint32_t budget = r->view->snap_exposure || r->frame_index == 0 ? s->count : per_frame, done = 0;
    uint32_t first = s->next;
    for (uint32_t k = 0; k < s->count && done < budget; k++) {
        uint32_t cube = (first + k) % s->count;
        if (!stale(&s->lit[cube], &now) && !r->params.relight_always)
            continue;
        if (done) /* the chain is the last cube's until its prefilter has read it */
            sb_renderer_barrier(r->cmd);
        relight(r, s, cube);
        s->lit[cube] = now;
        s->next = (cube + 1) % s->count;
        done++;
    }
}

const struct sb_pass_class sb_pass_reflections = {
    .name = "reflections",
    .create = reflections_create,
    .destroy = reflections_destroy,
    .record = reflections_record,
};

const float *sb_renderer_reflection_cubes(const struct sb_renderer *r, uint32_t *count, uint32_t *face_size,
                                          uint32_t *levels)
{
    const struct reflections *s = r->pass_data[SB_PASS_REFLECTIONS];
    *count = s ? s->count : 0;
    *face_size = s ? s->face_size : 0;
    *levels = s ? s->levels : 0;
    return s && s->count ? s->cubes.mapped : NULL;
}
