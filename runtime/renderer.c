#include "renderer_internal.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "aerial_perspective.spv.h"
#include "bloom_down.spv.h"
#include "bloom_up.spv.h"
#include "compute.h"
#include "exposure.spv.h"
#include "histogram.spv.h"
#include "image.h"
#include "log.h"
#include "physics.h"
#include "pipeline.h"
#include "probe_light.spv.h"
#include "probe_sky.spv.h"
#include "scene.h"
#include "scene_frag.spv.h"
#include "scene_frag_volume.spv.h"
#include "scene_vert.spv.h"
#include "sh.h"
#include "shadow_vert.spv.h"
#include "shadows.h"
#include "sky.spv.h"
#include "sky_from_space.spv.h"
#include "sky_view.spv.h"
#include "texture.h"
#include "tonemap.spv.h"
#include "transform.h"

#define NEAR_M 0.1
#define AERIAL_FAR_KM 32.0
/* The cascades' depth: 16 bits resolve 1 cm over the largest cascade's
 * depth range (two radii of 238 m and the 200 m caster margin), far under
 * its 23 cm texels, and halve what the H100's 8 ROPs clear and write
 * (0.61 ms to 0.37 at 1080p, the test world). */
#define SHADOW_FORMAT VK_FORMAT_D16_UNORM

static const struct sb_pass_class *const pass_classes[SB_PASS_COUNT];

const char *sb_pass_name(enum sb_pass pass)
{
    return pass < SB_PASS_COUNT ? pass_classes[pass]->name : "?";
}

int sb_pass_toggles(uint32_t toggles[SB_PASS_COUNT])
{
    int n = 0;
    for (int p = 0; p < SB_PASS_COUNT; p++) {
        if (!pass_classes[p]->optional || pass_classes[p]->needs)
            continue;
        uint32_t mask = 1u << p;
        for (int q = 0; q < SB_PASS_COUNT; q++)
            if (pass_classes[q]->optional && (pass_classes[q]->needs >> p & 1))
                mask |= 1u << q;
        toggles[n++] = mask;
    }
    return n;
}

static const struct {
    const uint32_t *words;
    size_t size;
    const char *name;
} kernel_spirv[KERNEL_COUNT] = {
    [KERNEL_SKY_VIEW] = {sb_spv_sky_view, sizeof(sb_spv_sky_view), "sky-view"},
    [KERNEL_AERIAL] = {sb_spv_aerial_perspective, sizeof(sb_spv_aerial_perspective), "aerial perspective"},
    [KERNEL_SKY] = {sb_spv_sky, sizeof(sb_spv_sky), "sky"},
    [KERNEL_SKY_FROM_SPACE] = {sb_spv_sky_from_space, sizeof(sb_spv_sky_from_space), "sky from space"},
    [KERNEL_HISTOGRAM] = {sb_spv_histogram, sizeof(sb_spv_histogram), "histogram"},
    [KERNEL_EXPOSURE] = {sb_spv_exposure, sizeof(sb_spv_exposure), "exposure"},
    [KERNEL_BLOOM_DOWN] = {sb_spv_bloom_down, sizeof(sb_spv_bloom_down), "bloom down"},
    [KERNEL_BLOOM_UP] = {sb_spv_bloom_up, sizeof(sb_spv_bloom_up), "bloom up"},
    [KERNEL_TONEMAP] = {sb_spv_tonemap, sizeof(sb_spv_tonemap), "tonemap"},
    [KERNEL_PROBE_SKY] = {sb_spv_probe_sky, sizeof(sb_spv_probe_sky), "probe sky"},
    [KERNEL_PROBE_LIGHT] = {sb_spv_probe_light, sizeof(sb_spv_probe_light), "probe light"},
};

/* ---- Declarations ----------------------------------------------------------------- */

void sb_pass_read_atmosphere(struct sb_renderer *r)
{
    sb_pass_use(r, SB_BINDING_ATMOSPHERE, sb_pass_find(r, "atmosphere"), SB_USE_LOAD);
    /* read by texelFetch (atmosphere.glsl, SB_ATMOSPHERE_TEXTURES) */
    sb_pass_sample(r, SB_BINDING_TRANSMITTANCE, sb_pass_find(r, "transmittance"), r->nearest);
    sb_pass_sample(r, SB_BINDING_MULTISCATTERING, sb_pass_find(r, "multiscattering"), r->nearest);
    sb_pass_sample(r, SB_BINDING_IRRADIANCE_GROUND, sb_pass_find(r, "irradiance ground"), r->nearest);
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
}

sb_resource sb_pass_find(struct sb_renderer *r, const char *name)
{
    sb_resource id = sb_graph_find(r, name);
    if (!id)
        sb_error("skyview: the %s pass uses \"%s\", which no earlier pass made", pass_classes[r->pass]->name, name);
    assert(id);
    return id;
}

/* The renderer's own resources in the graph's table. */
static void add_resources(struct sb_renderer *r)
{
    const struct {
        const char *name;
        const struct sb_buffer *buffer;
    } buffers[] = {
        {"atmosphere", &r->atmosphere},   {"frame", &r->frame},
        {"vertices", &r->vertices},       {"exposure", &r->exposure},
        {"probes", &r->probes},           {"probe light", &r->probe_light},
        {"reflections", &r->reflections}, {"reflection cubes", &r->reflection_cubes},
    };
    for (size_t i = 0; i < sizeof(buffers) / sizeof(buffers[0]); i++)
        sb_graph_buffer(r, buffers[i].name, buffers[i].buffer);
    if (r->scene_traced) {
        sb_graph_buffer(r, "bvh nodes", &r->bvh_nodes);
        sb_graph_buffer(r, "bvh triangles", &r->bvh_triangles);
    }
    const struct {
        const char *name;
        struct sb_texture *texture;
    } images[] = {
        {"transmittance", &r->transmittance},
        {"multiscattering", &r->multiscattering},
        {"irradiance ground", &r->irradiance_ground},
        {"aerial", &r->aerial},
        {"aerial transmittance", &r->aerial_t},
        {"shadow cascades", &r->shadow},
        {"depth", &r->depth},
        {"bloom", &r->bloom},
    };
    for (size_t i = 0; i < sizeof(images) / sizeof(images[0]); i++)
        sb_graph_image(r, images[i].name, images[i].texture);
    r->hdr_id = sb_graph_image(r, "hdr", &r->hdr);
    r->ldr_id = sb_graph_image(r, "ldr", &r->ldr);
    r->sky_view_id = sb_graph_image(r, "sky-view", &r->sky_view);
}

/* ---- Creation ------------------------------------------------------------------ */

static enum sb_result upload(struct sb_vk *vk, const void *data, size_t bytes, const char *name, struct sb_buffer *b)
{
    enum sb_result res = sb_buffer_create(vk, bytes, name, b);
    if (!res && data)
        memcpy(b->mapped, data, bytes);
    return res;
}

enum sb_result sb_renderer_upload(struct sb_renderer *r, const void *data, size_t bytes, const char *name,
                                  struct sb_buffer *buffer)
{
    return upload(r->vk, data, bytes, name, buffer);
}

enum sb_result sb_renderer_kernel(struct sb_renderer *r, const uint32_t *spirv, size_t spirv_size, const char *name,
                                  VkPipeline *pipeline)
{
    VkPipelineLayout layout;
    enum sb_result res = sb_pass_layout(r, &layout);
    return res ? res : sb_compute_pipeline_create(r->vk, layout, spirv, spirv_size, name, pipeline);
}

/* One of the renderer's kernels, for the pass being created. */
static enum sb_result create_kernel(struct sb_renderer *r, enum compute_kernel k)
{
    return sb_renderer_kernel(r, kernel_spirv[k].words, kernel_spirv[k].size, kernel_spirv[k].name, &r->kernels[k]);
}

enum sb_result sb_renderer_upload_image(struct sb_renderer *r, const struct sb_image *image, bool volume, float fill,
                                        const char *name, struct sb_texture *texture)
{
    uint32_t size[3] = {1, 1, volume ? 2 : 1}; /* a depth of 2 keeps a stand-in 3D */
    if (image) {
        size[0] = image->width;
        size[1] = image->height;
        size[2] = image->depth ? image->depth : 1;
    }
    size_t texels = (size_t)size[0] * size[1] * size[2];
    uint16_t *data = malloc(texels * 4 * sizeof(uint16_t));
    if (!data)
        return SB_ERR_NOMEM;
    for (size_t i = 0; i < texels; i++)
        for (uint32_t c = 0; c < 4; c++) {
            float v = image && c < image->channel_count ? image->data[i * image->channel_count + c] : fill;
            data[4 * i + c] = sb_half_from_float(v);
        }
    struct sb_texture_params p = {
        .width = size[0],
        .height = size[1],
        .depth = size[2],
        .format = VK_FORMAT_R16G16B16A16_SFLOAT,
        .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
        .name = name,
    };
    enum sb_result res = sb_texture_create(r->vk, &p, texture);
    if (!res)
        res = sb_texture_upload(r->vk, texture, data, texels * 4 * sizeof(uint16_t), 4 * sizeof(uint16_t));
    free(data);
    return res;
}

/* A sampled RGBA32F texture of width x height texels from `data`, `channels`
 * floats (3 or more) a texel: the first three, alpha 0. */
static enum sb_result upload_rgba32f(struct sb_renderer *r, const float *data, uint32_t channels, uint32_t width,
                                     uint32_t height, const char *name, struct sb_texture *texture)
{
    size_t texels = (size_t)width * height;
    float *rgba = channels == 4 ? NULL : malloc(texels * 4 * sizeof(float));
    if (channels != 4 && !rgba)
        return SB_ERR_NOMEM;
    for (size_t i = 0; rgba && i < texels; i++)
        for (uint32_t c = 0; c < 4; c++)
            rgba[4 * i + c] = c < 3 ? data[i * channels + c] : 0.0f;
    struct sb_texture_params p = {
        .width = width,
        .height = height,
        .format = VK_FORMAT_R32G32B32A32_SFLOAT,
        .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
        .name = name,
    };
    enum sb_result res = sb_texture_create(r->vk, &p, texture);
    if (!res)
        res = sb_texture_upload(r->vk, texture, rgba ? rgba : data, texels * 4 * sizeof(float), 4 * sizeof(float));
    free(rgba);
    return res;
}

static enum sb_result upload_atmosphere(struct sb_renderer *r, const struct sb_pack *pack)
{
    static const enum sb_product_id needed[] = {SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_MULTISCATTERING,
                                                SB_PRODUCT_IRRADIANCE_GROUND};
    for (size_t i = 0; i < sizeof(needed) / sizeof(needed[0]); i++)
        if (!pack->present[needed[i]]) {
            sb_error("the pack has no %s, which skyview needs: bake a scene that asks for it",
                     sb_product_name(needed[i]));
            return SB_ERR_USAGE;
        }
    const struct sb_atmosphere_params *atm = &pack->scene->atmosphere;
    struct sb_atmosphere_gpu gpu;
    sb_atmosphere_gpu_pack(atm, &gpu);
    double sun_max = fmax(atm->solar_irradiance[0], fmax(atm->solar_irradiance[1], atm->solar_irradiance[2]));
    r->radiance_scale = sun_max > 0.0 ? 1.0 / sun_max : 1.0;
    r->frame_scale = r->previous_frame_scale = r->next_frame_scale = r->readback_scale = r->radiance_scale;
    r->ground_radius_km = atm->ground_radius_km;
    r->thickness_km = gpu.radii[3];

    const struct sb_image *t = &pack->images[SB_PRODUCT_TRANSMITTANCE];
    enum sb_result res = upload(r->vk, &gpu, sizeof(gpu), "atmosphere parameters", &r->atmosphere);
    /* Each as RGBA32F (atmosphere.glsl, SB_ATMOSPHERE_TEXTURES): the
     * transmittance LUT; psi_ms refined; the ground irradiance's lookup form. */
    if (!res)
        res = upload_rgba32f(r, t->data, t->channel_count, t->width, t->height, "transmittance", &r->transmittance);
    float *refined = res ? NULL : malloc(sb_multiscattering_refined_float_count() * sizeof(float));
    if (!res && !refined)
        res = SB_ERR_NOMEM;
    if (!res) {
        sb_multiscattering_refined_fill(&pack->images[SB_PRODUCT_MULTISCATTERING], refined);
        res = upload_rgba32f(r, refined, 4, SB_MULTISCATTERING_REFINED_SIZE, SB_MULTISCATTERING_REFINED_SIZE,
                             "multiscattering (refined)", &r->multiscattering);
    }
    free(refined);
    float ground[SB_IRRADIANCE_WIDTH * 2 * 3]; /* two rows (physics.h) */
    assert(sb_lookup_float_count(SB_PRODUCT_IRRADIANCE_GROUND) == sizeof(ground) / sizeof(ground[0]));
    if (!res) {
        sb_lookup_fill(SB_PRODUCT_IRRADIANCE_GROUND, &pack->images[SB_PRODUCT_IRRADIANCE_GROUND], ground);
        res = upload_rgba32f(r, ground, 3, SB_IRRADIANCE_WIDTH, 2, "irradiance_ground (lookup)", &r->irradiance_ground);
    }
    return res;
}

/* The world's mean albedo, weighted by area: the bounce model's surfaces. */
static void mean_albedo(const struct sb_world *world, float out[3])
{
    double sum[3] = {0, 0, 0}, area = 0;
    for (uint32_t v = 0; v + 2 < world->vertex_count; v += 3) {
        const struct sb_vertex_gpu *t = &world->vertices[v];
        double e1[3], e2[3];
        for (int i = 0; i < 3; i++) {
            e1[i] = (double)t[1].position[i] - t[0].position[i];
            e2[i] = (double)t[2].position[i] - t[0].position[i];
        }
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double a = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int i = 0; i < 3; i++)
            sum[i] += a * t[0].albedo[i];
        area += a;
    }
    for (int i = 0; i < 3; i++)
        out[i] = area > 0 ? (float)(sum[i] / area) : 0.0f;
}

/* Floats a probe takes in the probes buffer (config.h, probes.glsl). */
#define PROBE_FLOATS (4 * SB_PROBE_VEC4S)

/*
 * The pack's sky-visibility probes, or none: the grid's probes (explicit
 * ones are for other uses: a runtime interpolates a grid), each as
 * (position, valid), its 9 SH coefficients; the tensor's non-zero entries;
 * the light buffer the probes pass writes.
 */
static enum sb_result upload_probes(struct sb_renderer *r, const struct sb_pack *pack, const struct sb_world *world)
{
    const struct sb_probe_layout *layout = &pack->artifacts[SB_PRODUCT_SKY_VISIBILITY].probes;
    const struct sb_image *image = &pack->images[SB_PRODUCT_SKY_VISIBILITY];
    uint64_t grid = (uint64_t)layout->grid[0] * layout->grid[1] * layout->grid[2];
    bool use = pack->present[SB_PRODUCT_SKY_VISIBILITY] && !r->params.no_probes && grid > 0 && grid <= image->width &&
               image->channel_count == SB_SKY_VISIBILITY_CHANNEL_COUNT;
    if (pack->present[SB_PRODUCT_SKY_VISIBILITY] && !r->params.no_probes && !use)
        sb_warn("the pack's sky_visibility has no probe grid: the world is lit by the sky alone");
    r->probe_count = use ? (uint32_t)grid : 0;
    size_t count = r->probe_count ? r->probe_count : 1;
    enum sb_result res =
        upload(r->vk, NULL, sizeof(struct sb_probes_gpu) + count * PROBE_FLOATS * sizeof(float), "probes", &r->probes);
    if (!res)
        res = upload(r->vk, NULL, (SB_PROBE_SH + count * SB_PROBE_SH) * 4 * sizeof(float), "probe light",
                     &r->probe_light);
    if (res || !r->probe_count)
        return res;
    struct sb_probes_gpu *g = r->probes.mapped;
    double t[SB_PROBE_SH][SB_PROBE_SH][SB_PROBE_SH]; /* 5.8 KB; not static: renderers on other threads */
    sb_sh9_tensor(t);
    uint32_t entries = 0;
    for (int i = 0; i < SB_PROBE_SH; i++)
        for (int j = 0; j < SB_PROBE_SH; j++)
            for (int k = 0; k < SB_PROBE_SH; k++)
                if (t[i][j][k] != 0 && entries < SB_SH_TENSOR_MAX) {
                    float *e = g->tensor[entries++];
                    e[0] = (float)t[i][j][k];
                    e[1] = (float)i;
                    e[2] = (float)j;
                    e[3] = (float)k;
                }
    for (int k = 0; k < 3; k++) {
        g->grid[k] = layout->grid[k];
        g->origin_m[k] = layout->origin_m[k];
        g->spacing_m[k] = layout->spacing_m[k];
    }
    g->grid[3] = r->probe_count;
    g->origin_m[3] = (float)entries;
    mean_albedo(world, g->bounce_albedo);
    const struct sb_image *bounce = &pack->images[SB_PRODUCT_SKY_BOUNCE];
    const struct sb_probe_layout *bounce_layout = &pack->artifacts[SB_PRODUCT_SKY_BOUNCE].probes;
    bool has_bounce = pack->present[SB_PRODUCT_SKY_BOUNCE] && bounce->width == image->width &&
                      !memcmp(bounce_layout->grid, layout->grid, sizeof(layout->grid));
    if (pack->present[SB_PRODUCT_SKY_BOUNCE] && !has_bounce)
        sb_warn("the pack's sky_bounce has another grid than its sky_visibility: the bounce is modelled");
    g->spacing_m[3] = has_bounce ? 1.0f : 0.0f;
    float *out = (float *)(g + 1);
    for (uint32_t p = 0; p < r->probe_count; p++) {
        const float *c = &image->data[(size_t)p * SB_SKY_VISIBILITY_CHANNEL_COUNT];
        float *o = &out[PROBE_FLOATS * (size_t)p];
        if (has_bounce)
            memcpy(o + 4 * SB_PROBE_BOUNCE_VEC4, &bounce->data[(size_t)p * SB_SKY_BOUNCE_CHANNEL_COUNT],
                   SB_BOUNCE_FLOATS * sizeof(float));
        memcpy(o, c + SB_SKY_VISIBILITY_POSITION, 3 * sizeof(float)); /* after any push out of geometry */
        o[3] = c[SB_SKY_VISIBILITY_VALID];
        /* The visibility as projected, the deringing window undone where it
         * can be: windowing before the product with the sky would blur the
         * horizon into the ground (open ground lost 17% of its sky light);
         * the irradiance is clamped at the end instead. */
        static const int band[SB_PROBE_SH] = {SB_SH_BANDS};
        double w[3];
        sb_sh9_window_factors(c[SB_SKY_VISIBILITY_DERING_WINDOW], w);
        const float *sh = c + SB_SKY_VISIBILITY_SH;
        for (int k = 0; k < SB_PROBE_SH; k++)
            o[4 + k] = w[band[k]] > 1e-3 ? (float)(sh[k] / w[band[k]]) : sh[k];
    }
    sb_info("probes: %u x %u x %u, %.3g m apart, light the world (bounce %s)", layout->grid[0], layout->grid[1],
            layout->grid[2], (double)layout->spacing_m[0], has_bounce ? "baked" : "modelled");
    return SB_OK;
}

/*
 * The pack's reflection probes (reflections.glsl), or none: the cubes
 * reordered from the pack's level-major image to one chain a cube, the
 * probes' positions and boxes, and the DFG LUT when the pack has it (else
 * the shader's analytic fit). The sky-only cube's irradiance on an upward
 * surface, for relighting under another sun.
 */
static enum sb_result upload_reflections(struct sb_renderer *r, const struct sb_pack *pack)
{
    const struct sb_image *cubes = &pack->images[SB_PRODUCT_REFLECTION_CUBES];
    const struct sb_image *records = &pack->images[SB_PRODUCT_REFLECTION_PROBES];
    bool use = pack->present[SB_PRODUCT_REFLECTION_CUBES] && pack->present[SB_PRODUCT_REFLECTION_PROBES] &&
               !r->params.no_reflections && records->width == cubes->depth && cubes->levels < 16; /* [3].w: the chain */
    bool dfg = use && pack->present[SB_PRODUCT_DFG];
    uint32_t count = use ? cubes->depth : 0, n = use ? cubes->width : 1, levels = use ? cubes->levels : 1;
    uint64_t chain = 0;
    for (uint32_t l = 0; l < levels; l++)
        chain += 6ull * sb_image_level_size(n, l) * sb_image_level_size(n, l);
    size_t header_vec4s = (sizeof(struct sb_reflections_gpu) + 15) / 16;
    size_t vec4s = header_vec4s + 3 * (size_t)count + (dfg ? (size_t)SB_DFG_SIZE * SB_DFG_SIZE : 0);
    enum sb_result res = upload(r->vk, NULL, vec4s * 16, "reflection probes", &r->reflections);
    if (!res)
        res = upload(r->vk, NULL, (use ? chain * count : 1) * 16, "reflection cubes", &r->reflection_cubes);
    if (res || !use)
        return res;
    struct sb_reflections_gpu *g = r->reflections.mapped;
    g->info[0] = n;
    g->info[1] = levels;
    g->info[2] = count;
    r->reflection_count = count;
    g->info[3] = dfg;
    double el = pack->scene->view.sun_elevation_deg * M_PI / 180, az = pack->scene->view.sun_azimuth_deg * M_PI / 180;
    double sun[3];
    sb_direction(az, el, sun);
    for (int k = 0; k < 3; k++)
        g->baked_sun[k] = (float)sun[k];
    /* The sky-only cube's irradiance SH (its record's channels 9 on, k then rgb) at +y. */
    const double up[3] = {0, 1, 0};
    for (int c = 0; c < 3; c++) {
        double coefficients[SB_PROBE_SH];
        for (int k = 0; k < SB_PROBE_SH; k++)
            coefficients[k] = records->data[9 + 3 * k + c];
        g->baked_sky_up[c] = (float)sb_sh9_eval(coefficients, up);
    }
    uint64_t at = 0;
    for (uint32_t l = 0; l < levels; l++) {
        g->level_offsets[l / 4][l % 4] = (uint32_t)at;
        at += 6ull * sb_image_level_size(n, l) * sb_image_level_size(n, l);
    }
    g->level_offsets[3][3] = (uint32_t)chain;
    float *data = (float *)r->reflections.mapped + 4 * header_vec4s;
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
    float *texels = r->reflection_cubes.mapped;
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

static enum sb_result create_texture(struct sb_renderer *r, struct sb_texture *t, uint32_t w, uint32_t h,
                                     uint32_t depth, uint32_t layers, uint32_t mips, VkFormat format,
                                     VkImageUsageFlags usage, const char *name)
{
    struct sb_texture_params p = {
        .width = w,
        .height = h,
        .depth = depth,
        .layers = layers,
        .mips = mips,
        .format = format,
        .usage = usage,
        .name = name,
    };
    return sb_texture_create(r->vk, &p, t);
}

static enum sb_result create_images(struct sb_renderer *r)
{
    const VkImageUsageFlags storage_sampled = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    const VkImageUsageFlags copy = VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    uint32_t s = r->scene_traced ? 1 : r->params.shadow_size; /* traced: never drawn nor read */
    uint32_t bw = r->width / 2 ? r->width / 2 : 1, bh = r->height / 2 ? r->height / 2 : 1;
    enum sb_result res = create_texture(r, &r->sky_view, SB_SKY_VIEW_WIDTH, SB_SKY_VIEW_HEIGHT, 1, 1, 1, SB_HDR_FORMAT,
                                        storage_sampled | copy, "sky-view LUT");
    if (!res)
        res = create_texture(r, &r->aerial, SB_AERIAL_SIZE, SB_AERIAL_SIZE, SB_AERIAL_SIZE, 1, 1, SB_HDR_FORMAT,
                             storage_sampled, "aerial perspective in-scattering");
    if (!res)
        res = create_texture(r, &r->aerial_t, SB_AERIAL_SIZE, SB_AERIAL_SIZE, SB_AERIAL_SIZE, 1, 1, SB_HDR_FORMAT,
                             storage_sampled, "aerial perspective transmittance");
    if (!res)
        res =
            create_texture(r, &r->shadow, s, s, 1, SB_CASCADES, 1, SHADOW_FORMAT,
                           VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, "shadow cascades");
    if (!res)
        res = create_texture(r, &r->hdr, r->width, r->height, 1, 1, 1, SB_HDR_FORMAT,
                             storage_sampled | copy | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                 VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                             "HDR frame");
    /* the traced scene writes its depth from a kernel, which a depth format cannot take */
    if (!res && r->scene_traced)
        res = create_texture(r, &r->depth, r->width, r->height, 1, 1, 1, VK_FORMAT_R32_SFLOAT, storage_sampled,
                             "scene depth (traced)");
    if (!res && !r->scene_traced)
        res = create_texture(r, &r->depth, r->width, r->height, 1, 1, 1, SB_DEPTH_FORMAT,
                             VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, "scene depth");
    if (!res)
        res = create_texture(r, &r->bloom, bw, bh, 1, 1, r->bloom_levels > 1 ? r->bloom_levels : 2, SB_HDR_FORMAT,
                             storage_sampled, "bloom chain");
    if (!res)
        res = create_texture(r, &r->ldr, r->width, r->height, 1, 1, 1, VK_FORMAT_R8G8B8A8_UNORM,
                             VK_IMAGE_USAGE_STORAGE_BIT | copy, "LDR frame");
    if (res)
        return res;

    struct sb_vk *vk = r->vk;
    VkSamplerCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = VK_FILTER_LINEAR,
        .minFilter = VK_FILTER_LINEAR,
        .mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
        .addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .maxLod = VK_LOD_CLAMP_NONE,
    };
    VK(vkCreateSampler(vk->device, &info, NULL, &r->linear));
    info.magFilter = info.minFilter = VK_FILTER_NEAREST;
    VK(vkCreateSampler(vk->device, &info, NULL, &r->nearest));
    info.magFilter = info.minFilter = VK_FILTER_LINEAR;
    info.compareEnable = VK_TRUE;
    info.compareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
    VK(vkCreateSampler(vk->device, &info, NULL, &r->shadow_compare));
    info.compareEnable = VK_FALSE;
    info.addressModeU = info.addressModeV = info.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    VK(vkCreateSampler(vk->device, &info, NULL, &r->repeat));
cleanup:
    return res;
}

enum sb_result sb_renderer_create(struct sb_vk *vk, const struct sb_pack *pack, const struct sb_world *world,
                                  const struct sb_renderer_params *params, struct sb_renderer **out)
{
    enum sb_result res = SB_OK;
    *out = NULL;
    if (!vk->graphics) {
        sb_error("skyview needs a Vulkan context created for graphics");
        return SB_ERR_USAGE;
    }
    if (!pack->scene) {
        sb_error("the pack has no scene");
        return SB_ERR_USAGE;
    }
    struct sb_renderer *r = calloc(1, sizeof(*r));
    if (!r)
        return SB_ERR_NOMEM;
    r->vk = vk;
    r->params = *params;
    r->width = params->width ? params->width : 1280;
    r->height = params->height ? params->height : 720;
    if (!r->params.shadow_size)
        r->params.shadow_size = 2048;
    if (r->params.shadow_distance_m <= 0.0)
        r->params.shadow_distance_m = 250.0;
    if (r->params.bloom_strength == 0.0)
        r->params.bloom_strength = 0.15;
    uint32_t shorter = r->width < r->height ? r->width : r->height;
    r->bloom_levels = 0;
    if (r->params.bloom_strength > 0.0)
        while (r->bloom_levels < SB_BLOOM_MAX_LEVELS && (shorter >> (r->bloom_levels + 1)) >= 4)
            r->bloom_levels++;
    r->vertex_count = world->vertex_count;
    r->caster_first_vertex = world->caster_first_vertex;
    r->scene_traced = sb_scene_trace_wanted(&r->params, vk, world->vertex_count);
    for (int i = 0; i < 3; i++) {
        r->world_min_m[i] = world->vertex_count ? INFINITY : 0.0;
        r->world_max_m[i] = world->vertex_count ? -INFINITY : 0.0;
    }
    for (uint32_t v = 0; v < world->vertex_count; v++)
        for (int i = 0; i < 3; i++) {
            r->world_min_m[i] = fmin(r->world_min_m[i], world->vertices[v].position[i]);
            r->world_max_m[i] = fmax(r->world_max_m[i], world->vertices[v].position[i]);
        }
    bool failed;
    r->caster_box_count =
        sb_caster_boxes(world->vertices, world->caster_first_vertex, world->vertex_count, &r->caster_boxes, &failed);
    if (failed) {
        res = SB_ERR_NOMEM;
        goto cleanup;
    }

    if ((res = upload_atmosphere(r, pack)))
        goto cleanup;
    res = upload(vk, world->vertices, world->vertex_count * sizeof(struct sb_vertex_gpu), "world", &r->vertices);
    if (!res)
        res = upload_probes(r, pack, world);
    if (!res)
        res = upload_reflections(r, pack);
    if (!res)
        res = upload(vk, NULL, sizeof(struct sb_frame_gpu), "frame constants", &r->frame);
    if (!res)
        res = upload(vk, NULL, SB_HISTOGRAM_BINS * sizeof(uint32_t) + sizeof(struct sb_exposure_gpu), "exposure",
                     &r->exposure);
    if (!res)
        res = upload(vk, NULL, (size_t)r->width * r->height * 4, "LDR readback", &r->read_ldr);
    if (!res)
        res = upload(vk, NULL, (size_t)r->width * r->height * 8, "HDR readback", &r->read_hdr);
    if (!res && params->post_input) {
        res = upload(vk, NULL, (size_t)r->width * r->height * 8, "post-processing input", &r->post_input);
        uint16_t *dst = res ? NULL : r->post_input.mapped;
        for (size_t i = 0; dst && i < (size_t)r->width * r->height; i++)
            for (int c = 0; c < 4; c++) {
                float v = c < 3 ? params->post_input[3 * i + c] : 1.0f;
                double stored = isfinite(v) ? v * r->radiance_scale : 0.0; /* within a half's range */
                dst[4 * i + c] = sb_half_from_float((float)fmin(fmax(stored, -65504.0), 65504.0));
            }
    }
    if (!res)
        res = upload(vk, NULL, (size_t)SB_SKY_VIEW_WIDTH * SB_SKY_VIEW_HEIGHT * 8, "sky-view readback",
                     &r->read_sky_view);
    if (!res)
        res = create_images(r);
    if (!res)
        res = sb_scene_trace_create(r, world);
    r->graph.passes = calloc(SB_PASS_COUNT, sizeof(*r->graph.passes));
    if (!res && !r->graph.passes)
        res = SB_ERR_NOMEM;
    if (!res)
        add_resources(r);
    r->pack = pack;
    for (r->pass = 0; r->pass < SB_PASS_COUNT && !res; r->pass++)
        if (assert(pass_classes[r->pass]), pass_classes[r->pass]->create)
            res = pass_classes[r->pass]->create(r);
    r->pack = NULL;
    /* The lit frame is whole before the first post-processing pass; when
     * one of them writes it, what they made is read back too. */
    r->first_post = SB_PASS_COUNT;
    for (int p = SB_PASS_COUNT; p-- > 0;)
        if (pass_classes[p]->post)
            r->first_post = p;
    for (int p = r->first_post; !res && p < SB_PASS_COUNT; p++)
        for (uint32_t u = 0; u < r->graph.passes[p].use_count; u++) {
            const struct sb_graph_use *use = &r->graph.passes[p].uses[u];
            r->post_in_place |= use->resource == r->hdr_id && use->use != SB_USE_SAMPLED && use->use != SB_USE_LOAD;
        }
    if (!res && r->post_in_place)
        res = upload(vk, NULL, (size_t)r->width * r->height * 8, "post-processed HDR readback", &r->read_post);
    if (!res)
        res = sb_graph_write_sets(r);
    if (res)
        goto cleanup;

    if (vk->has_timestamps) {
        VkQueryPoolCreateInfo qinfo = {
            .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
            .queryType = VK_QUERY_TYPE_TIMESTAMP,
            .queryCount = 2 * SB_PASS_COUNT,
        };
        VK(vkCreateQueryPool(vk->device, &qinfo, NULL, &r->queries));
    }
    VkCommandBufferAllocateInfo alloc = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = vk->command_pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    VK(vkAllocateCommandBuffers(vk->device, &alloc, &r->cmd));
    VkFenceCreateInfo finfo = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK(vkCreateFence(vk->device, &finfo, NULL, &r->fence));
    *out = r;
    return SB_OK;

cleanup:
    sb_renderer_destroy(&r);
    return res;
}

void sb_renderer_destroy(struct sb_renderer **pr)
{
    struct sb_renderer *r = *pr;
    if (!r)
        return;
    struct sb_vk *vk = r->vk;
    VkDevice d = vk->device;
    vkDeviceWaitIdle(d);
    if (r->fence)
        vkDestroyFence(d, r->fence, NULL);
    free(r->caster_boxes);
    if (r->cmd)
        vkFreeCommandBuffers(d, vk->command_pool, 1, &r->cmd);
    if (r->queries)
        vkDestroyQueryPool(d, r->queries, NULL);
    for (int p = SB_PASS_COUNT; p-- > 0;)
        if (pass_classes[p]->destroy)
            pass_classes[p]->destroy(r);
    sb_scene_trace_destroy(r);
    const VkPipeline raster[] = {r->shadow_pipeline, r->scene_pipeline, r->scene_volume_pipeline};
    sb_renderer_release(r, r->kernels, KERNEL_COUNT, NULL, 0);
    sb_renderer_release(r, raster, 3, NULL, 0);
    sb_graph_destroy(r);
    if (r->linear)
        vkDestroySampler(d, r->linear, NULL);
    if (r->nearest)
        vkDestroySampler(d, r->nearest, NULL);
    if (r->shadow_compare)
        vkDestroySampler(d, r->shadow_compare, NULL);
    if (r->repeat)
        vkDestroySampler(d, r->repeat, NULL);
    struct sb_texture *const textures[] = {&r->transmittance,
                                           &r->multiscattering,
                                           &r->irradiance_ground,
                                           &r->sky_view,
                                           &r->aerial,
                                           &r->aerial_t,
                                           &r->shadow,
                                           &r->hdr,
                                           &r->depth,
                                           &r->bloom,
                                           &r->ldr};
    sb_renderer_release(r, NULL, 0, textures, sizeof(textures) / sizeof(textures[0]));
    struct sb_buffer *buffers[] = {&r->atmosphere,  &r->frame,       &r->vertices,         &r->exposure,
                                   &r->read_ldr,    &r->read_hdr,    &r->read_sky_view,    &r->probes,
                                   &r->probe_light, &r->reflections, &r->reflection_cubes, &r->read_post,
                                   &r->post_input};
    for (size_t i = 0; i < sizeof(buffers) / sizeof(buffers[0]); i++)
        sb_buffer_destroy(vk, buffers[i]);
    free(r);
    *pr = NULL;
}

/* ---- A frame ------------------------------------------------------------------- */

static void store4(float dst[4], double x, double y, double z, double w)
{
    dst[0] = (float)x;
    dst[1] = (float)y;
    dst[2] = (float)z;
    dst[3] = (float)w;
}

static void fill_frame(struct sb_renderer *r, const struct sb_view *v, struct sb_frame_gpu *f)
{
    memset(f, 0, sizeof(*f));
    double fov = v->fov_y > 0.0 ? v->fov_y : 50.0 * M_PI / 180.0;
    double aspect = (double)r->width / r->height;
    double forward[3], sun[3];
    sb_direction(v->yaw, v->pitch, forward);
    sb_direction(v->sun_azimuth, v->sun_elevation, sun);
    double up[3] = {0.0, 1.0, 0.0};
    if (fabs(forward[1]) > 0.999) { /* looking straight up or down: yaw decides what is up */
        sb_direction(v->yaw, 0.0, up);
        if (forward[1] > 0.0)
            for (int i = 0; i < 3; i++)
                up[i] = -up[i];
    }
    struct sb_mat4 view = sb_mat4_look(forward, up);
    struct sb_mat4 proj = sb_mat4_perspective(fov, aspect, NEAR_M);
    r->view_proj = sb_mat4_mul(&proj, &view);
    memcpy(r->camera_m, v->camera_m, sizeof(r->camera_m));
    struct sb_mat4 inv = sb_mat4_inverse(&r->view_proj);
    sb_mat4_store(&r->view_proj, f->view_proj);
    sb_mat4_store(&inv, f->inv_view_proj);

    struct sb_cascade_params cp = {
        .near_m = NEAR_M,
        .distance_m = r->params.shadow_distance_m,
        .lambda = 0.75,
        .fov_y = fov,
        .aspect = aspect,
        .map_size = r->params.shadow_size,
        .caster_margin_m = 200.0,
    };
    struct sb_cascades cascades;
    sb_cascades_compute(&cp, v->camera_m, forward, sun, &cascades);
    for (int c = 0; c < SB_CASCADES; c++) {
        sb_mat4_store(&cascades.view_proj[c], f->shadow_view_proj[c]);
        f->cascade_ends[c] = (float)cascades.ends_m[c];
        f->cascade_texel[c] = (float)cascades.texel_m[c];
        /* Texels to clear and draw: the casters' box and a margin each side
         * that covers what the lookups read (config.h); they see the sun
         * outside, exactly as if the whole map were cleared and drawn. */
        int32_t box[4], size = (int32_t)r->params.shadow_size;
        int32_t *clear = r->cascade_clear[c];
        if (r->params.whole_shadow_maps) {
            box[0] = box[1] = 0;
            box[2] = box[3] = size;
        } else {
            sb_cascade_caster_rect(&cascades.view_proj[c], v->camera_m, r->caster_boxes, r->caster_box_count,
                                   r->params.shadow_size, box);
        }
        for (int k = 0; k < 2; k++) {
            clear[k] = box[k] - SB_SHADOW_CLEAR_MARGIN_TEXELS > 0 ? box[k] - SB_SHADOW_CLEAR_MARGIN_TEXELS : 0;
            clear[k + 2] =
                box[k + 2] + SB_SHADOW_CLEAR_MARGIN_TEXELS < size ? box[k + 2] + SB_SHADOW_CLEAR_MARGIN_TEXELS : size;
        }
        if (box[0] >= box[2]) { /* no casters: nothing to draw, every lookup lit */
            clear[0] = clear[1] = clear[2] = clear[3] = 0;
            store4(f->cascade_rect[c], 2.0, 2.0, -1.0, -1.0);
        } else {
            const double m = SB_SHADOW_RECT_MARGIN_TEXELS;
            store4(f->cascade_rect[c], (box[0] - m) / size, (box[1] - m) / size, (box[2] + m) / size,
                   (box[3] + m) / size);
        }
    }

    const double R = r->ground_radius_km;
    double km[3] = {v->camera_m[0] * 1e-3, R + v->camera_m[1] * 1e-3, v->camera_m[2] * 1e-3};
    double altitude = sqrt(km[0] * km[0] + km[1] * km[1] + km[2] * km[2]) - R;
    const double sun_radius = 0.2666 * M_PI / 180.0; /* the sun's mean angular radius */
    store4(f->camera_m, v->camera_m[0], v->camera_m[1], v->camera_m[2], NEAR_M);
    store4(f->camera_km, km[0], km[1], km[2], altitude);
    /* the shaders' test, on the same fp32 values */
    r->camera_in_atmosphere = (float)altitude < r->thickness_km;
    /* Every fragment lies in the world's box: when its farthest corner is
     * inside the aerial-perspective volume's range (1% to spare for fp32),
     * no fragment needs the ray's integral (aerial.glsl). */
    double reach2 = 0.0;
    for (int i = 0; i < 3; i++) {
        double d = fmax(fabs(r->world_min_m[i] - v->camera_m[i]), fabs(r->world_max_m[i] - v->camera_m[i]));
        reach2 += d * d;
    }
    r->aerial_volume_only =
        !r->params.generic_shaders && r->camera_in_atmosphere && sqrt(reach2) <= 0.99e3 * AERIAL_FAR_KM;
    store4(f->camera_forward, forward[0], forward[1], forward[2], cos(sun_radius));
    store4(f->sun_direction, sun[0], sun[1], sun[2], sun_radius);
    store4(f->shadow, 0.1, 1.5, r->params.shadow_size, 1.0);
    store4(f->aerial, AERIAL_FAR_KM, r->frame_scale, 0.0, 0.0);
    /* Bins 1 to 255 span 2^-20 to 2^12 of the solar irradiance's units:
     * from nautical twilight (the sun 12 to 14 degrees down, where the
     * exposure stops following the light and night falls) to beyond the
     * sun-lit snow. */
    double log_sun = log2(1.0 / r->radiance_scale);
    store4(f->exposure, log_sun - 20.0, 32.0, 0.10, 0.90);
    store4(f->adaptation, 3.0, 1.0, v->dt_s > 0.0 ? v->dt_s : 1.0 / 60.0, v->snap_exposure ? 1.0 : 0.0);
    bool bloom = r->params.bloom_strength > 0.0 && !(v->disabled_passes >> SB_PASS_BLOOM & 1);
    store4(f->post, 1.0, bloom ? r->params.bloom_strength : 0.0, r->params.exposure_compensation_ev, r->params.tonemap);
    f->size[0] = r->width;
    f->size[1] = r->height;
    f->size[2] = bloom ? r->bloom_levels : 0; /* none: the tone curve reads no bloom (never written this frame) */
    f->size[3] = (uint32_t)r->params.debug;
}

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

void sb_renderer_release(struct sb_renderer *r, const VkPipeline *pipelines, size_t pipeline_count,
                         struct sb_texture *const *textures, size_t texture_count)
{
    for (size_t i = 0; i < pipeline_count; i++)
        if (pipelines[i])
            vkDestroyPipeline(r->vk->device, pipelines[i], NULL);
    for (size_t i = 0; i < texture_count; i++)
        sb_texture_destroy(r->vk, textures[i]);
}

static void dispatch_on(struct sb_renderer *r, VkPipeline pipeline, uint32_t set, const struct sb_view_push *push,
                        const uint32_t size[3], const uint32_t group[3])
{
    const struct sb_graph_pass *p = &r->graph.passes[r->pass];
    struct sb_view_push none = {0};
    assert(set < p->set_count);
    vkCmdBindPipeline(r->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(r->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->layout, 0, 1, &p->sets[set], 0, NULL);
    vkCmdPushConstants(r->cmd, p->layout, VK_SHADER_STAGE_ALL, 0, sizeof(none), push ? push : &none);
    vkCmdDispatch(r->cmd, (size[0] + group[0] - 1) / group[0], (size[1] + group[1] - 1) / group[1],
                  (size[2] + group[2] - 1) / group[2]);
}

void sb_renderer_dispatch(struct sb_renderer *r, VkPipeline pipeline, const struct sb_view_push *push,
                          const uint32_t size[3], const uint32_t group[3])
{
    dispatch_on(r, pipeline, 0, push, size, group);
}

void sb_renderer_dispatch_set(struct sb_renderer *r, uint32_t set, VkPipeline pipeline, const struct sb_view_push *push,
                              const uint32_t size[3], const uint32_t group[3])
{
    dispatch_on(r, pipeline, set, push, size, group);
}

void sb_renderer_bind_graphics(struct sb_renderer *r, VkPipeline pipeline, const struct sb_view_push *push)
{
    const struct sb_graph_pass *p = &r->graph.passes[r->pass];
    struct sb_view_push none = {0};
    vkCmdBindPipeline(r->cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    vkCmdBindDescriptorSets(r->cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p->layout, 0, 1, &p->sets[0], 0, NULL);
    vkCmdPushConstants(r->cmd, p->layout, VK_SHADER_STAGE_ALL, 0, sizeof(none), push ? push : &none);
}

/* A 2D dispatch of one of the renderer's kernels. */
static void dispatch(struct sb_renderer *r, enum compute_kernel k, uint32_t set, const struct sb_view_push *push,
                     uint32_t width, uint32_t height, uint32_t group_x, uint32_t group_y)
{
    dispatch_on(r, r->kernels[k], set, push, (const uint32_t[3]){width, height, 1},
                (const uint32_t[3]){group_x, group_y, 1});
}

static void set_viewport(VkCommandBuffer cmd, uint32_t w, uint32_t h)
{
    VkViewport viewport = {0.0f, 0.0f, (float)w, (float)h, 0.0f, 1.0f};
    VkRect2D scissor = {{0, 0}, {w, h}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

/* ---- The renderer's passes ------------------------------------------------------- */

static enum sb_result sky_view_create(struct sb_renderer *r)
{
    sb_pass_read_atmosphere(r);
    sb_pass_use(r, SB_VIEW_BINDING_SKY_VIEW_OUT, r->sky_view_id, SB_USE_STORE);
    return create_kernel(r, KERNEL_SKY_VIEW);
}

static void record_sky_view(struct sb_renderer *r)
{
    dispatch(r, KERNEL_SKY_VIEW, 0, NULL, SB_SKY_VIEW_WIDTH, SB_SKY_VIEW_HEIGHT, SB_WORKGROUP_X, SB_WORKGROUP_Y);
}

static enum sb_result probes_create(struct sb_renderer *r)
{
    if (!r->probe_count)
        return SB_OK;
    sb_pass_read_atmosphere(r);
    sb_pass_sample(r, SB_VIEW_BINDING_SKY_VIEW, r->sky_view_id, NULL);
    sb_pass_use(r, SB_VIEW_BINDING_PROBES, sb_pass_find(r, "probes"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_PROBE_LIGHT, sb_pass_find(r, "probe light"), SB_USE_LOAD_STORE);
    enum sb_result res = create_kernel(r, KERNEL_PROBE_SKY);
    return res ? res : create_kernel(r, KERNEL_PROBE_LIGHT);
}

static void record_probes(struct sb_renderer *r)
{
    if (!r->probe_count)
        return;
    dispatch(r, KERNEL_PROBE_SKY, 0, NULL, 1, 1, 1, 1);
    sb_renderer_barrier(r->cmd);
    dispatch(r, KERNEL_PROBE_LIGHT, 0, NULL, r->probe_count, 1, SB_PROBE_THREADS, 1);
}

static enum sb_result aerial_create(struct sb_renderer *r)
{
    sb_pass_read_atmosphere(r);
    sb_pass_use(r, SB_VIEW_BINDING_AERIAL_OUT, sb_pass_find(r, "aerial"), SB_USE_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_AERIAL_T_OUT, sb_pass_find(r, "aerial transmittance"), SB_USE_STORE);
    return create_kernel(r, KERNEL_AERIAL);
}

static void record_aerial(struct sb_renderer *r)
{
    dispatch(r, KERNEL_AERIAL, 0, NULL, SB_AERIAL_SIZE, SB_AERIAL_SIZE, SB_WORKGROUP_X, SB_WORKGROUP_Y);
}

static enum sb_result shadows_create(struct sb_renderer *r)
{
    if (r->scene_traced) /* shadow rays instead */
        return SB_OK;
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_VERTICES, sb_pass_find(r, "vertices"), SB_USE_LOAD);
    sb_pass_use(r, SB_NO_BINDING, sb_pass_find(r, "shadow cascades"), SB_USE_DEPTH_TARGET);
    struct sb_graphics_pipeline_params shadow = {
        .vertex_spirv = sb_spv_shadow_vert,
        .vertex_size = sizeof(sb_spv_shadow_vert),
        .depth_format = SHADOW_FORMAT,
        .depth_compare = VK_COMPARE_OP_LESS,
        .depth_clamp = true, /* casters behind the near plane still cast ("pancaking") */
        .depth_bias_constant = 1.0f,
        .depth_bias_slope = 1.5f,
        .name = "shadow cascades",
    };
    enum sb_result res = sb_pass_layout(r, &shadow.layout);
    return res ? res : sb_graphics_pipeline_create(r->vk, &shadow, &r->shadow_pipeline);
}

/* Depth attachments are written in the attachment-optimal layout (a general
 * one costs NVIDIA its depth compression: the H200 drew the cascades in
 * 2.46 ms from the general layout, 1.30 ms from this one)
 * and read in the read-only one (graph.c). Their contents do not survive a frame. */
#define DEPTH_WRITE VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL

static void record_shadows(struct sb_renderer *r)
{
    if (r->scene_traced) /* shadow rays instead */
        return;
    uint32_t s = r->params.shadow_size;
    sb_renderer_bind_graphics(r, r->shadow_pipeline, NULL);
    const VkPipelineLayout layout = r->graph.passes[r->pass].layout;
    for (uint32_t c = 0; c < SB_CASCADES; c++) {
        const int32_t *clear = r->cascade_clear[c];
        if (clear[0] >= clear[2] || clear[1] >= clear[3])
            continue;
        VkRect2D area = {{clear[0], clear[1]}, {(uint32_t)(clear[2] - clear[0]), (uint32_t)(clear[3] - clear[1])}};
        VkRenderingAttachmentInfo depth = {
            .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
            .imageView = r->shadow.subviews[c],
            .imageLayout = DEPTH_WRITE,
            .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
            .clearValue = {.depthStencil = {1.0f, 0}},
        };
        VkRenderingInfo info = {
            .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
            .renderArea = area,
            .layerCount = 1,
            .pDepthAttachment = &depth,
        };
        vkCmdBeginRendering(r->cmd, &info);
        set_viewport(r->cmd, s, s);
        vkCmdSetScissor(r->cmd, 0, 1, &area);
        struct sb_view_push push = {.cascade = c};
        vkCmdPushConstants(r->cmd, layout, VK_SHADER_STAGE_ALL, 0, sizeof(push), &push);
        vkCmdDraw(r->cmd, r->vertex_count - r->caster_first_vertex, 1, r->caster_first_vertex, 0);
        vkCmdEndRendering(r->cmd);
    }
}

static enum sb_result scene_create(struct sb_renderer *r)
{
    sb_pass_read_atmosphere(r);
    sb_pass_use(r, SB_VIEW_BINDING_VERTICES, sb_pass_find(r, "vertices"), SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_AERIAL, sb_pass_find(r, "aerial"), NULL);
    sb_pass_sample(r, SB_VIEW_BINDING_AERIAL_T, sb_pass_find(r, "aerial transmittance"), NULL);
    static const struct {
        uint32_t binding;
        const char *name;
    } buffers[] = {
        {SB_VIEW_BINDING_PROBES, "probes"},           {SB_VIEW_BINDING_PROBE_LIGHT, "probe light"},
        {SB_VIEW_BINDING_REFLECTIONS, "reflections"}, {SB_VIEW_BINDING_REFLECTION_CUBES, "reflection cubes"},
        {SB_VIEW_BINDING_CLOUDS, "clouds"},
    };
    for (size_t i = 0; i < sizeof(buffers) / sizeof(buffers[0]); i++)
        sb_pass_use(r, buffers[i].binding, sb_pass_find(r, buffers[i].name), SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_CLOUD_SHADOW, sb_pass_find(r, "cloud shadow"), NULL);
    if (r->scene_traced)
        return sb_scene_trace_create_pass(r);
    sb_pass_sample(r, SB_VIEW_BINDING_SHADOW, sb_pass_find(r, "shadow cascades"), r->shadow_compare);
    sb_pass_use(r, SB_NO_BINDING, r->hdr_id, SB_USE_COLOR_TARGET);
    sb_pass_use(r, SB_NO_BINDING, sb_pass_find(r, "depth"), SB_USE_DEPTH_TARGET);
    /* scene.frag's specialization: what the pack holds */
    bool generic = r->params.generic_shaders;
    const VkBool32 has[2] = {generic || r->probe_count > 0, generic || r->reflection_count > 0};
    const VkSpecializationMapEntry entries[2] = {
        {.constantID = 0, .offset = 0, .size = sizeof(VkBool32)},
        {.constantID = 1, .offset = sizeof(VkBool32), .size = sizeof(VkBool32)},
    };
    const VkSpecializationInfo specialization = {
        .mapEntryCount = 2, .pMapEntries = entries, .dataSize = sizeof(has), .pData = has};
    struct sb_graphics_pipeline_params scene = {
        .fragment_specialization = &specialization,
        .vertex_spirv = sb_spv_scene_vert,
        .vertex_size = sizeof(sb_spv_scene_vert),
        .fragment_spirv = sb_spv_scene_frag,
        .fragment_size = sizeof(sb_spv_scene_frag),
        .color_format = SB_HDR_FORMAT,
        .depth_format = SB_DEPTH_FORMAT,
        .depth_compare = VK_COMPARE_OP_GREATER, /* reverse Z */
        .name = "scene",
    };
    enum sb_result res = sb_pass_layout(r, &scene.layout);
    if (!res)
        res = sb_graphics_pipeline_create(r->vk, &scene, &r->scene_pipeline);
    scene.fragment_spirv = sb_spv_scene_frag_volume;
    scene.fragment_size = sizeof(sb_spv_scene_frag_volume);
    scene.name = "scene (aerial volume only)";
    if (!res)
        res = sb_graphics_pipeline_create(r->vk, &scene, &r->scene_volume_pipeline);
    return res;
}

static void record_scene(struct sb_renderer *r)
{
    if (r->scene_traced) {
        sb_scene_trace_record(r);
        return;
    }
    VkRenderingAttachmentInfo color = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = r->hdr.view,
        .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
    };
    VkRenderingAttachmentInfo depth = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = r->depth.view,
        .imageLayout = DEPTH_WRITE,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        .clearValue = {.depthStencil = {0.0f, 0}}, /* reverse Z: 0 is infinitely far */
    };
    VkRenderingInfo info = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
        .renderArea = {{0, 0}, {r->width, r->height}},
        .layerCount = 1,
        .colorAttachmentCount = 1,
        .pColorAttachments = &color,
        .pDepthAttachment = &depth,
    };
    vkCmdBeginRendering(r->cmd, &info);
    set_viewport(r->cmd, r->width, r->height);
    sb_renderer_bind_graphics(r, r->aerial_volume_only ? r->scene_volume_pipeline : r->scene_pipeline, NULL);
    vkCmdDraw(r->cmd, r->vertex_count, 1, 0, 0);
    vkCmdEndRendering(r->cmd);
}

static enum sb_result sky_create(struct sb_renderer *r)
{
    sb_pass_read_atmosphere(r);
    sb_pass_sample(r, SB_VIEW_BINDING_SKY_VIEW, r->sky_view_id, NULL);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, r->hdr_id, SB_USE_LOAD_STORE);
    sb_pass_sample(r, SB_VIEW_BINDING_DEPTH, sb_pass_find(r, "depth"), r->nearest);
    enum sb_result res = create_kernel(r, KERNEL_SKY);
    return res ? res : create_kernel(r, KERNEL_SKY_FROM_SPACE);
}

static void record_sky(struct sb_renderer *r)
{
    dispatch(r, r->camera_in_atmosphere ? KERNEL_SKY : KERNEL_SKY_FROM_SPACE, 0, NULL, r->width, r->height,
             SB_WORKGROUP_X, SB_WORKGROUP_Y);
}

static enum sb_result exposure_create(struct sb_renderer *r)
{
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_EXPOSURE, sb_pass_find(r, "exposure"), SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, r->hdr_id, SB_USE_LOAD);
    enum sb_result res = create_kernel(r, KERNEL_HISTOGRAM);
    return res ? res : create_kernel(r, KERNEL_EXPOSURE);
}

static void record_exposure(struct sb_renderer *r)
{
    dispatch(r, KERNEL_HISTOGRAM, 0, NULL, r->width, r->height, 16, 16);
    sb_renderer_barrier(r->cmd);
    dispatch(r, KERNEL_EXPOSURE, 0, NULL, 1, 1, 1, 1);
}

/* Bloom's steps, a set each: down step i reads level i - 1 (the frame for
 * i = 0) and writes level i; up step i reads level i + 1 and adds into
 * level i. */
static enum sb_result bloom_create(struct sb_renderer *r)
{
    if (!r->bloom_levels)
        return SB_OK;
    sb_resource bloom = sb_pass_find(r, "bloom");
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_EXPOSURE, sb_pass_find(r, "exposure"), SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_BLOOM_SRC, r->hdr_id, NULL);
    sb_pass_use(r, SB_VIEW_BINDING_BLOOM_DST, bloom, SB_USE_LOAD_STORE);
    sb_pass_sets(r, SB_BLOOM_SETS);
    VkImageView mip[SB_BLOOM_MAX_LEVELS];
    for (uint32_t i = 0; i < SB_BLOOM_MAX_LEVELS; i++)
        mip[i] = r->bloom.subview_count ? r->bloom.subviews[i < r->bloom_levels ? i : 0] : r->bloom.view;
    for (uint32_t i = 0; i < SB_BLOOM_MAX_LEVELS; i++) {
        if (i > 0)
            sb_pass_set_view(r, i, SB_VIEW_BINDING_BLOOM_SRC, mip[i - 1]);
        sb_pass_set_view(r, i, SB_VIEW_BINDING_BLOOM_DST, mip[i]);
        sb_pass_set_view(r, SB_BLOOM_MAX_LEVELS + i, SB_VIEW_BINDING_BLOOM_SRC,
                         mip[i + 1 < SB_BLOOM_MAX_LEVELS ? i + 1 : i]);
        sb_pass_set_view(r, SB_BLOOM_MAX_LEVELS + i, SB_VIEW_BINDING_BLOOM_DST, mip[i]);
    }
    enum sb_result res = create_kernel(r, KERNEL_BLOOM_DOWN);
    return res ? res : create_kernel(r, KERNEL_BLOOM_UP);
}

static void record_bloom(struct sb_renderer *r)
{
    if (!r->bloom_levels)
        return;
    uint32_t w = r->bloom.width, h = r->bloom.height;
    for (uint32_t i = 0; i < r->bloom_levels; i++) {
        struct sb_view_push push = {.level = i, .first_level = i == 0};
        dispatch(r, KERNEL_BLOOM_DOWN, i, &push, w >> i ? w >> i : 1, h >> i ? h >> i : 1, SB_WORKGROUP_X,
                 SB_WORKGROUP_Y);
        if (r->bloom_levels > 1) /* the up steps read it */
            sb_renderer_barrier(r->cmd);
    }
    for (uint32_t i = r->bloom_levels - 1; i-- > 0;) {
        struct sb_view_push push = {.level = i};
        dispatch(r, KERNEL_BLOOM_UP, SB_BLOOM_MAX_LEVELS + i, &push, w >> i ? w >> i : 1, h >> i ? h >> i : 1,
                 SB_WORKGROUP_X, SB_WORKGROUP_Y);
        if (i > 0)
            sb_renderer_barrier(r->cmd);
    }
}

static enum sb_result tonemap_create(struct sb_renderer *r)
{
    sb_resource bloom = sb_pass_find(r, "bloom");
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_EXPOSURE, sb_pass_find(r, "exposure"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, r->hdr_id, SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_BLOOM, bloom, NULL);
    sb_pass_set_view(r, 0, SB_VIEW_BINDING_BLOOM, r->bloom.subview_count ? r->bloom.subviews[0] : r->bloom.view);
    sb_pass_use(r, SB_VIEW_BINDING_LDR, r->ldr_id, SB_USE_STORE);
    return create_kernel(r, KERNEL_TONEMAP);
}

static void record_tonemap(struct sb_renderer *r)
{
    dispatch(r, KERNEL_TONEMAP, 0, NULL, r->width, r->height, SB_WORKGROUP_X, SB_WORKGROUP_Y);
}

static const struct sb_pass_class pass_sky_view = {
    .name = "sky-view", .create = sky_view_create, .record = record_sky_view};
static const struct sb_pass_class pass_probes = {.name = "probes", .create = probes_create, .record = record_probes};
static const struct sb_pass_class pass_aerial = {
    .name = "aerial perspective", .create = aerial_create, .record = record_aerial};
static const struct sb_pass_class pass_shadows = {
    .name = "shadows", .create = shadows_create, .record = record_shadows};
static const struct sb_pass_class pass_scene = {.name = "scene", .create = scene_create, .record = record_scene};
static const struct sb_pass_class pass_sky = {.name = "sky", .create = sky_create, .record = record_sky};
static const struct sb_pass_class pass_exposure = {
    .name = "exposure", .post = true, .create = exposure_create, .record = record_exposure};
/* Left out, the tone curve adds no bloom (fill_frame). */
static const struct sb_pass_class pass_bloom = {
    .name = "bloom", .post = true, .create = bloom_create, .record = record_bloom, .optional = true};
static const struct sb_pass_class pass_tonemap = {
    .name = "tonemap", .post = true, .create = tonemap_create, .record = record_tonemap};

/* A frame's passes, in order (enum sb_pass). */
static const struct sb_pass_class *const pass_classes[SB_PASS_COUNT] = {
    [SB_PASS_SKY_VIEW] = &pass_sky_view,
    [SB_PASS_PROBES] = &pass_probes,
    [SB_PASS_AERIAL_PERSPECTIVE] = &pass_aerial,
    [SB_PASS_SHADOWS] = &pass_shadows,
    [SB_PASS_CLOUD_SHADOW] = &sb_pass_cloud_shadow, /* clouds.c */
    [SB_PASS_FOG] = &sb_pass_fog,                   /* fog.c */
    [SB_PASS_SCENE] = &pass_scene,
    [SB_PASS_SKY] = &pass_sky,
    [SB_PASS_CLOUDS] = &sb_pass_clouds,       /* clouds.c */
    [SB_PASS_FOG_APPLY] = &sb_pass_fog_apply, /* fog.c */
    [SB_PASS_PURKINJE] = &sb_pass_purkinje,   /* purkinje.c */
    [SB_PASS_EXPOSURE] = &pass_exposure,
    [SB_PASS_LOCAL_TONEMAP] = &sb_pass_local_tonemap, /* local_tonemap.c */
    [SB_PASS_GRADE_LINEAR] = &sb_pass_grade_linear,   /* grade.c */
    [SB_PASS_BLOOM] = &pass_bloom,
    [SB_PASS_TONEMAP] = &pass_tonemap,
    [SB_PASS_GRADE] = &sb_pass_grade, /* grade.c */
};

/* A readback: the whole of an image into a host-visible buffer. */
static void copy_image(struct sb_renderer *r, sb_resource image, const struct sb_buffer *b)
{
    const struct sb_texture *t = sb_graph_texture(r, image);
    VkBufferImageCopy region = {
        .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
        .imageExtent = {t->width, t->height, 1},
    };
    sb_graph_access(r, image, SB_USE_COPY_SRC);
    vkCmdCopyImageToBuffer(r->cmd, t->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, b->buffer, 1, &region);
}

/* The lit frame replaced by params.post_input's (its halves, uploaded once). */
static void copy_input(struct sb_renderer *r)
{
    VkBufferImageCopy region = {
        .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
        .imageExtent = {r->width, r->height, 1},
    };
    sb_graph_access(r, r->hdr_id, SB_USE_COPY_DST);
    vkCmdCopyBufferToImage(r->cmd, r->post_input.buffer, r->hdr.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                           &region);
}

/*
 * Pre-exposure: the frame is stored in halves as radiance times a scale that
 * follows the exposure, so whatever the light, mid grey is stored within
 * half a stop of 2^-PRE_EXPOSURE_EV (0.011; exposed, 0.18): 13 stops above the
 * halves' subnormals and 20 below their largest (the sun's disk at noon
 * fits). A fixed scale put twilight among the subnormals and night below
 * them. The scale is the radiance scale times a power of two, so a frame
 * reads back the same, bit for bit, whichever it was stored at, away from
 * the halves' limits (a value subnormal at one scale and not at the other
 * differs by its rounding). The next frame's comes from this frame's
 * adapted exposure (a cut's from its metered one), so a frame's scale
 * depends on the frame before alone; the fog's and clouds' histories are
 * rescaled by the ratio as they are read. A post_input is stored at the
 * radiance scale, so with one the scale stays that.
 */
#define PRE_EXPOSURE_EV 4
/* A cut whose metered scale is more than this many stops from the one it
 * was drawn with is drawn again with the metered one (once). */
#define PRE_EXPOSURE_REDRAW_EV 3
#define PRE_EXPOSURE_MIN_EV (-16)
#define PRE_EXPOSURE_MAX_EV 24

static double metered_frame_scale(const struct sb_renderer *r)
{
    if (r->params.post_input)
        return r->radiance_scale;
    float state[4];
    sb_renderer_exposure(r, state);
    double stops = log2((double)state[1] / r->radiance_scale) - PRE_EXPOSURE_EV;
    if (!isfinite(stops))
        return r->frame_scale;
    stops = fmin(fmax(round(stops), PRE_EXPOSURE_MIN_EV), PRE_EXPOSURE_MAX_EV);
    return r->radiance_scale * exp2(stops);
}

static enum sb_result render_once(struct sb_renderer *r, const struct sb_view *view, bool readback,
                                  struct sb_frame_timings *timings);

enum sb_result sb_renderer_render(struct sb_renderer *r, const struct sb_view *view, bool readback,
                                  struct sb_frame_timings *timings)
{
    r->previous_frame_scale = r->frame_scale;
    r->frame_scale = r->next_frame_scale;
    if (view->fixed_pre_exposure && !r->params.post_input)
        r->frame_scale =
            r->radiance_scale * exp2(fmin(fmax(view->pre_exposure_stops, PRE_EXPOSURE_MIN_EV), PRE_EXPOSURE_MAX_EV));
    enum sb_result res = render_once(r, view, readback, timings);
    if (res)
        return res;
    r->next_frame_scale = metered_frame_scale(r);
    if (view->snap_exposure && !view->fixed_pre_exposure &&
        fabs(log2(r->next_frame_scale / r->frame_scale)) > PRE_EXPOSURE_REDRAW_EV) {
        /* A cut keeps no history, so drawing it again gives the frame it
         * would have been with the right scale; the same jitter too. */
        r->frame_scale = r->next_frame_scale;
        r->frame_index--;
        if ((res = render_once(r, view, readback, timings)))
            return res;
        r->next_frame_scale = metered_frame_scale(r);
    }
    if (readback)
        r->readback_scale = r->frame_scale;
    return SB_OK;
}

static enum sb_result render_once(struct sb_renderer *r, const struct sb_view *view, bool readback,
                                  struct sb_frame_timings *timings)
{
    enum sb_result res = SB_OK;
    struct sb_vk *vk = r->vk;
    fill_frame(r, view, r->frame.mapped);
    r->view = view;

    VK(vkResetCommandBuffer(r->cmd, 0));
    VkCommandBufferBeginInfo begin = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    VK(vkBeginCommandBuffer(r->cmd, &begin));
    sb_graph_begin_frame(r);
    if (r->queries)
        vkCmdResetQueryPool(r->cmd, r->queries, 0, 2 * SB_PASS_COUNT);

    /* A pass whose input was left out is left out too (its `needs`); the
     * passes come in order, so one sweep settles it. */
    uint32_t disabled = 0;
    for (int p = 0; p < SB_PASS_COUNT; p++)
        if (pass_classes[p]->optional && (view->disabled_passes >> p & 1 || (disabled & pass_classes[p]->needs) != 0))
            disabled |= 1u << p;
    for (r->pass = 0; r->pass < SB_PASS_COUNT; r->pass++) {
        int p = r->pass;
        if (p == r->first_post) { /* the lit frame is whole: post-processing takes it from here */
            if (r->params.post_input)
                copy_input(r);
            if (readback)
                copy_image(r, r->hdr_id, &r->read_hdr);
        }
        /* A pass's time: from the end of every command before it to the end
         * of its own, what it adds to the frame where passes overlap. */
        if (r->queries)
            vkCmdWriteTimestamp(r->cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, r->queries, 2 * p);
        if (disabled >> p & 1) {
            if (pass_classes[p]->skipped)
                pass_classes[p]->skipped(r);
        } else {
            sb_graph_before_pass(r, p);
            pass_classes[p]->record(r);
        }
        if (r->queries)
            vkCmdWriteTimestamp(r->cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, r->queries, 2 * p + 1);
    }

    if (readback) {
        copy_image(r, r->ldr_id, &r->read_ldr);
        if (r->post_in_place)
            copy_image(r, r->hdr_id, &r->read_post);
        copy_image(r, r->sky_view_id, &r->read_sky_view);
    }
    sb_graph_end_frame(r);
    VkMemoryBarrier to_host = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_HOST_READ_BIT,
    };
    vkCmdPipelineBarrier(r->cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                         NULL, 0, NULL);
    VK(vkEndCommandBuffer(r->cmd));
    VK(vkResetFences(vk->device, 1, &r->fence));
    VkSubmitInfo submit = {
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
        .commandBufferCount = 1,
        .pCommandBuffers = &r->cmd,
    };
    VK(vkQueueSubmit(vk->queue, 1, &submit, r->fence));
    VK(vkWaitForFences(vk->device, 1, &r->fence, VK_TRUE, UINT64_MAX));
    r->view = NULL;
    r->frame_index++;

    if (timings) {
        memset(timings, 0, sizeof(*timings));
        if (r->queries) {
            uint64_t ts[2 * SB_PASS_COUNT];
            VK(vkGetQueryPoolResults(vk->device, r->queries, 0, 2 * SB_PASS_COUNT, sizeof(ts), ts, sizeof(uint64_t),
                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
            double to_ms = vk->timestamp_period_ns * 1e-6;
            for (int p = 0; p < SB_PASS_COUNT; p++)
                timings->ms[p] = (double)(ts[2 * p + 1] - ts[2 * p]) * to_ms;
            timings->total_ms = (double)(ts[2 * SB_PASS_COUNT - 1] - ts[0]) * to_ms;
            timings->valid = true;
        }
    }
cleanup:
    return res;
}

/* ---- Reading back ---------------------------------------------------------------- */

void sb_renderer_size(const struct sb_renderer *r, uint32_t *width, uint32_t *height)
{
    *width = r->width;
    *height = r->height;
}

const uint8_t *sb_renderer_ldr(const struct sb_renderer *r)
{
    return r->read_ldr.mapped;
}

static void halves_to_rgb(const uint16_t *src, size_t pixels, double scale, float *rgb)
{
    for (size_t i = 0; i < pixels; i++)
        for (int c = 0; c < 3; c++)
            rgb[i * 3 + c] = (float)(sb_half_to_float(src[i * 4 + c]) / scale);
}

double sb_renderer_stored_scale(const struct sb_renderer *r)
{
    return r->readback_scale;
}

void sb_renderer_hdr(const struct sb_renderer *r, float *rgb)
{
    halves_to_rgb(r->read_hdr.mapped, (size_t)r->width * r->height, r->readback_scale, rgb);
}

void sb_renderer_post_hdr(const struct sb_renderer *r, float *rgb)
{
    const struct sb_buffer *b = r->post_in_place ? &r->read_post : &r->read_hdr;
    halves_to_rgb(b->mapped, (size_t)r->width * r->height, r->readback_scale, rgb);
}

void sb_renderer_sky_view(const struct sb_renderer *r, float *rgb)
{
    halves_to_rgb(r->read_sky_view.mapped, (size_t)SB_SKY_VIEW_WIDTH * SB_SKY_VIEW_HEIGHT, r->readback_scale, rgb);
}

void sb_renderer_exposure(const struct sb_renderer *r, float state[4])
{
    const struct sb_exposure_gpu *e =
        (const struct sb_exposure_gpu *)((const uint32_t *)r->exposure.mapped + SB_HISTOGRAM_BINS);
    memcpy(state, e->state, 4 * sizeof(float));
}

bool sb_renderer_project(const struct sb_renderer *r, const double world_m[3], double pixel[2])
{
    double rel[3] = {world_m[0] - r->camera_m[0], world_m[1] - r->camera_m[1], world_m[2] - r->camera_m[2]};
    const double *m = r->view_proj.m;
    double w = m[3] * rel[0] + m[7] * rel[1] + m[11] * rel[2] + m[15];
    if (w <= 0.0)
        return false;
    double ndc[3];
    sb_mat4_project(&r->view_proj, rel, ndc);
    pixel[0] = (ndc[0] * 0.5 + 0.5) * r->width;
    pixel[1] = (ndc[1] * 0.5 + 0.5) * r->height;
    return true;
}

void sb_renderer_pixel_ray(const struct sb_renderer *r, const double pixel[2], double direction[3])
{
    struct sb_mat4 inv = sb_mat4_inverse(&r->view_proj);
    double ndc[3] = {pixel[0] / r->width * 2.0 - 1.0, pixel[1] / r->height * 2.0 - 1.0, 0.5}, p[3];
    sb_mat4_project(&inv, ndc, p);
    double len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int i = 0; i < 3; i++)
        direction[i] = p[i] / len;
}
