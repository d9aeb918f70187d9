/*
 * The sky-visibility probes relit each frame (probes.glsl): the sky's SH
 * from the sky-view LUT (probe_sky), then each probe's irradiance SH from
 * its visibility and bounce (probe_light), which the scene and the fog
 * read. The pack's probe grid and detail are uploaded here; without them
 * the buffers hold a probe of zeros and the pass records nothing.
 * "probes", "probe light" and "probe detail" in the graph's table.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "probes_gpu.h"
#include "renderer_internal.h"
#include "sh.h"

#include "probe_light.spv.h"
#include "probe_sky.spv.h"

struct probes {
    struct sb_buffer probes, light; /* sb_probes_gpu and its probes; the sky's and probes' SH */
    struct sb_buffer detail;        /* the detail's table of brick columns (one absent one without) */
    struct sb_buffer sight;         /* the detail probes' sight masks (one word without) */
    VkPipeline sky_kernel, light_kernel;
    bool sky_only; /* no probes: the sky's SH alone, for the reflections' relight */
};

/* The world's mean albedo, weighted by area: the bounce model's surfaces.
 * An instanced world's triangles count once a copy, by their placed area
 * (cross(M a, M b) = det(M) M^-T cross(a, b): the normals' matrix). */
static void mean_albedo(const struct sb_world *world, float out[3])
{
    double sum[3] = {0, 0, 0}, area = 0;
    uint32_t copies = world->instance_count ? world->instance_count : 1;
    for (uint32_t i = 0; i < copies; i++) {
        const struct sb_world_mesh_range *range =
            world->instance_count ? &world->meshes[world->instance_mesh[i]] : NULL;
        const struct sb_instance_gpu *in = range ? &world->instances[i] : NULL;
        double det = 1.0;
        if (in) {
            const float(*m)[4] = in->to_world;
            det = fabs((double)m[0][0] * ((double)m[1][1] * m[2][2] - (double)m[1][2] * m[2][1]) -
                       (double)m[0][1] * ((double)m[1][0] * m[2][2] - (double)m[1][2] * m[2][0]) +
                       (double)m[0][2] * ((double)m[1][0] * m[2][1] - (double)m[1][1] * m[2][0]));
        }
        uint32_t first = range ? range->first_vertex : 0, end = range ? range->end_vertex : world->vertex_count;
        for (uint32_t v = first; v + 2 < end; v += 3) {
            const struct sb_vertex_gpu *t = &world->vertices[v];
            double e1[3], e2[3];
            for (int k = 0; k < 3; k++) {
                e1[k] = (double)t[1].position[k] - t[0].position[k];
                e2[k] = (double)t[2].position[k] - t[0].position[k];
            }
            double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
            if (in) {
                double placed[3];
                for (int r = 0; r < 3; r++)
                    placed[r] = det * (in->normal[r][0] * n[0] + in->normal[r][1] * n[1] + in->normal[r][2] * n[2]);
                memcpy(n, placed, sizeof(n));
            }
            double a = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (int k = 0; k < 3; k++)
                sum[k] += a * t[0].albedo[k];
            area += a;
        }
    }
    for (int i = 0; i < 3; i++)
        out[i] = area > 0 ? (float)(sum[i] / area) : 0.0f;
}

/* Whether the pack's product `id` (a bounce) goes with its sky_visibility,
 * probe for probe: the same layout; warned (`instead`: what lights the
 * world without it) when present but not. */
static bool goes_with_visibility(const struct sb_pack *pack, enum sb_product_id id, const char *instead)
{
    const struct sb_probe_layout *a = &pack->artifacts[SB_PRODUCT_SKY_VISIBILITY].probes,
                                 *b = &pack->artifacts[id].probes;
    bool same = pack->present[id] && pack->images[id].width == pack->images[SB_PRODUCT_SKY_VISIBILITY].width &&
                !memcmp(a->grid, b->grid, sizeof(a->grid)) && a->detail_count == b->detail_count;
    if (pack->present[id] && !same)
        sb_warn("the pack's %s has another grid than its sky_visibility: %s", sb_product_name(id), instead);
    return same;
}

/* Entries of the detail's table at most (64 MiB). */
#define SB_PROBES_MAX_DETAIL_TABLE (1u << 22)

/* The detail's table: an entry for each brick column of the lattice (x
 * fastest; probes_gpu.h), those the layout holds filled. Without detail,
 * one absent entry. */
static enum sb_result upload_detail(struct sb_renderer *r, struct probes *s, const struct sb_probe_layout *layout,
                                    uint32_t grid, struct sb_probes_gpu *g)
{
    uint32_t first = grid;
    uint32_t size[2] = {0, 0};
    for (uint32_t c = 0; c < layout->column_count && r->probe_count; c++) {
        size[0] = (uint32_t)layout->columns[c].x + 1 > size[0] ? (uint32_t)layout->columns[c].x + 1 : size[0];
        size[1] = (uint32_t)layout->columns[c].z + 1 > size[1] ? (uint32_t)layout->columns[c].z + 1 : size[1];
    }
    uint64_t entries = (uint64_t)size[0] * size[1];
    if (entries > SB_PROBES_MAX_DETAIL_TABLE) {
        sb_warn("the pack's detail probes span %u x %u brick columns, over the %u skyview's table holds: the "
                "grid's probes light the world alone",
                size[0], size[1], SB_PROBES_MAX_DETAIL_TABLE);
        entries = 0;
    }
    bool sight = entries && g && layout->sight;
    size_t words = sight ? (size_t)layout->detail_count * SB_PROBES_SIGHT_WORDS : 1;
    enum sb_result res =
        sb_renderer_upload(r, NULL, (entries ? entries : 1) * 4 * sizeof(uint32_t), "probe detail", &s->detail);
    if (!res)
        res = sb_renderer_upload(r, sight ? layout->sight : NULL, words * sizeof(uint32_t), "probe sight", &s->sight);
    if (res || !entries || !g)
        return res;
    uint32_t(*table)[4] = s->detail.mapped;
    for (uint32_t c = 0; c < layout->column_count; c++) {
        const struct sb_probe_column *col = &layout->columns[c];
        uint32_t *e = table[(uint64_t)col->z * size[0] + (uint32_t)col->x];
        e[0] = (uint32_t)col->y0;
        e[1] = col->rows;
        e[2] = first;
        e[3] = first - grid; /* its first detail probe's: its sight masks' */
        first += col->rows * SB_PROBES_BRICK * SB_PROBES_BRICK;
    }
    g->detail[0] = size[0];
    g->detail[1] = size[1];
    g->detail[2] = sight;
    g->detail[3] = layout->column_count;
    for (int k = 0; k < 3; k++)
        g->detail_origin_m[k] = layout->detail_origin_m[k];
    g->detail_origin_m[3] = layout->detail_spacing_m;
    return SB_OK;
}

void sb_pass_read_probes(struct sb_renderer *r)
{
    sb_pass_use(r, SB_VIEW_BINDING_PROBES, sb_pass_find(r, "probes"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_PROBE_LIGHT, sb_pass_find(r, "probe light"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_PROBE_DETAIL, sb_pass_find(r, "probe detail"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_PROBE_SIGHT, sb_pass_find(r, "probe sight"), SB_USE_LOAD);
}

/*
 * The pack's sky-visibility probes, or none: the grid's probes and the
 * detail's (explicit ones are for other uses: a runtime interpolates
 * between probes it knows the places of), each as
 * (position, valid), its 9 SH coefficients; the tensor's non-zero entries;
 * the light buffer the probes pass writes.
 */
static enum sb_result upload_probes(struct sb_renderer *r, struct probes *s)
{
    const struct sb_pack *pack = r->pack;
    const struct sb_probe_layout *layout = &pack->artifacts[SB_PRODUCT_SKY_VISIBILITY].probes;
    const struct sb_image *image = &pack->images[SB_PRODUCT_SKY_VISIBILITY];
    uint64_t grid = (uint64_t)layout->grid[0] * layout->grid[1] * layout->grid[2];
    uint64_t placed = grid + layout->detail_count;
    bool use = pack->present[SB_PRODUCT_SKY_VISIBILITY] && !r->params.no_probes && placed > 0 &&
               placed <= image->width && image->channel_count == SB_SKY_VISIBILITY_CHANNEL_COUNT;
    if (pack->present[SB_PRODUCT_SKY_VISIBILITY] && !r->params.no_probes && !use)
        sb_warn("the pack's sky_visibility has no probe grid or detail: the world is lit by the sky alone");
    r->probe_count = use ? (uint32_t)placed : 0;
    size_t count = r->probe_count ? r->probe_count : 1;
    const struct sb_image *bounce = &pack->images[SB_PRODUCT_SKY_BOUNCE];
    bool has_bounce = goes_with_visibility(pack, SB_PRODUCT_SKY_BOUNCE, "the bounce is modelled");
    /* the sun's table (sun_bounce) relights the sun's bounce; without it the
     * sun goes through sky_bounce's order-2 SH (docs/probes.md, "The sun") */
    bool sun_table =
        has_bounce && goes_with_visibility(pack, SB_PRODUCT_SUN_BOUNCE, "the sun's bounce through sky_bounce");
    const size_t floats = 4 * (sun_table ? SB_PROBE_SUN_VEC4S : SB_PROBE_VEC4S); /* a probe's (config.h) */
    enum sb_result res = sb_renderer_upload(r, NULL, sizeof(struct sb_probes_gpu) + count * floats * sizeof(float),
                                            "probes", &s->probes);
    if (!res)
        res = sb_renderer_upload(r, NULL, (SB_PROBE_SH + count * SB_PROBE_SH) * 4 * sizeof(float), "probe light",
                                 &s->light);
    if (!res)
        res = upload_detail(r, s, layout, (uint32_t)grid, r->probe_count ? s->probes.mapped : NULL);
    if (res || !r->probe_count)
        return res;
    struct sb_probes_gpu *g = s->probes.mapped;
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
    _Static_assert(SB_PROBES_MAX_LAYERS <= 8, "sb_probes_gpu holds 8 layers");
    g->layered[0] = layout->layer_count;
    for (uint32_t l = 0; l < layout->layer_count; l++)
        g->layers_m[l / 4][l % 4] = layout->layers_m[l];
    mean_albedo(r->world, g->bounce_albedo);
    g->spacing_m[3] = sun_table ? 2.0f : has_bounce ? 1.0f : 0.0f;
    float *out = (float *)(g + 1);
    for (uint32_t p = 0; p < r->probe_count; p++) {
        const float *c = &image->data[(size_t)p * SB_SKY_VISIBILITY_CHANNEL_COUNT];
        float *o = &out[floats * (size_t)p];
        if (has_bounce)
            memcpy(o + 4 * SB_PROBE_BOUNCE_VEC4, &bounce->data[(size_t)p * SB_SKY_BOUNCE_CHANNEL_COUNT],
                   SB_BOUNCE_FLOATS * sizeof(float));
        if (sun_table)
            memcpy(o + 4 * SB_PROBE_SUN_VEC4,
                   &pack->images[SB_PRODUCT_SUN_BOUNCE].data[(size_t)p * SB_SUN_BOUNCE_CHANNEL_COUNT],
                   SB_BOUNCE_SUN_TABLE * sizeof(float));
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
        if (layout->layer_count && p < grid) { /* the surface under its column: where it was placed, less its layer */
            uint32_t l = p / layout->grid[0] % layout->grid[1];
            o[13] = c[SB_SKY_VISIBILITY_POSITION + 1] - c[SB_SKY_VISIBILITY_OFFSET + 1] - layout->layers_m[l];
        }
    }
    if (layout->layer_count)
        sb_info("probes: %u x %u columns %.3g m apart, %u layers over the surface (%.3g to %.3g m), light the "
                "world (bounce %s%s)",
                layout->grid[0], layout->grid[2], (double)layout->spacing_m[0], layout->layer_count,
                (double)layout->layers_m[0], (double)layout->layers_m[layout->layer_count - 1],
                has_bounce ? "baked" : "modelled", sun_table ? ", the sun's from its table" : "");
    else
        sb_info("probes: %u x %u x %u, %.3g m apart, light the world (bounce %s%s)", layout->grid[0], layout->grid[1],
                layout->grid[2], (double)layout->spacing_m[0], has_bounce ? "baked" : "modelled",
                sun_table ? ", the sun's from its table" : "");
    if (layout->detail_count)
        sb_info("probes: detail %.3g m apart, %u probes in %u brick columns%s", (double)layout->detail_spacing_m,
                layout->detail_count, layout->column_count,
                layout->sight ? ", each seen only where it sees"
                              : " (without sight masks: light may leak through walls)");
    return SB_OK;
}

static enum sb_result probes_create(struct sb_renderer *r)
{
    struct probes *s = calloc(1, sizeof(*s));
    if (!s)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, s);
    enum sb_result res = upload_probes(r, s);
    if (res)
        return res;
    sb_resource probes = sb_graph_buffer(r, "probes", &s->probes);
    sb_resource light = sb_graph_buffer(r, "probe light", &s->light);
    sb_graph_buffer(r, "probe detail", &s->detail);
    sb_graph_buffer(r, "probe sight", &s->sight);
    s->sky_only = !r->probe_count && sb_reflections_relightable(r->pack, &r->params, r->world);
    if (!r->probe_count && !s->sky_only) /* the sky's SH is lit for the probes, or for the reflections' relight */
        return SB_OK;
    sb_pass_read_atmosphere(r);
    sb_pass_sample(r, SB_VIEW_BINDING_SKY_VIEW, sb_pass_find(r, "sky-view"), NULL);
    sb_pass_use(r, SB_VIEW_BINDING_PROBES, probes, SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_PROBE_LIGHT, light, SB_USE_LOAD_STORE);
    res = sb_renderer_kernel(r, sb_spv_probe_sky, sizeof(sb_spv_probe_sky), "probe sky", &s->sky_kernel);
    if (!res && r->probe_count)
        res = sb_renderer_kernel(r, sb_spv_probe_light, sizeof(sb_spv_probe_light), "probe light", &s->light_kernel);
    return res;
}

static void probes_destroy(struct sb_renderer *r)
{
    struct probes *s = sb_pass_data(r);
    if (!s)
        return;
    sb_buffer_destroy(r->vk, &s->probes);
    sb_buffer_destroy(r->vk, &s->light);
    sb_buffer_destroy(r->vk, &s->detail);
    sb_buffer_destroy(r->vk, &s->sight);
    free(s);
}

static void probes_record(struct sb_renderer *r)
{
    struct probes *s = sb_pass_data(r);
    if (!r->probe_count && !s->sky_only)
        return;
    sb_renderer_dispatch(r, s->sky_kernel, NULL, (const uint32_t[3]){1, 1, 1}, (const uint32_t[3]){1, 1, 1});
    if (!r->probe_count)
        return;
    sb_renderer_barrier(r->cmd);
    sb_renderer_dispatch(r, s->light_kernel, NULL, (const uint32_t[3]){r->probe_count, 1, 1},
                         (const uint32_t[3]){SB_PROBE_THREADS, 1, 1});
}

const struct sb_pass_class sb_pass_probes = {
    .name = "probes",
    .create = probes_create,
    .destroy = probes_destroy,
    .record = probes_record,
};
