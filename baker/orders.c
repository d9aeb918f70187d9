#include "orders.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere_ref.h"
#include "config.h"
#include "log.h"
#include "orders_density.spv.h"
#include "orders_directions.spv.h"
#include "orders_scatter.spv.h"
#include "orders_single.spv.h"
#include "orders_views.spv.h"
#include "physics.h"
#include "sky_error.h"

#define KERNEL(stage, texels)                                                                                          \
    {                                                                                                                  \
        .spirv = sb_spv_orders_##stage, .spirv_size = sizeof(sb_spv_orders_##stage),                                   \
        .binding_count = SB_ORDERS_BINDING_COUNT, .texel_bindings = (texels),                                          \
        .push_size = sizeof(struct sb_orders_push), .name = "orders " #stage,                                          \
    }
enum { SINGLE, VIEWS, DIRECTIONS, DENSITY, SCATTER, KERNEL_COUNT };
_Static_assert(KERNEL_COUNT == SB_ORDERS_KERNEL_COUNT, "the stages");
/* the density stage reads the directions, the scatter stage the views and
 * the density, as texels (sb_buffer_create_texels; orders.comp says why) */
static const struct sb_pipeline_params kernels[KERNEL_COUNT] = {
    KERNEL(single, 0), KERNEL(views, 0), KERNEL(directions, 0), KERNEL(density, 1u << SB_ORDERS_BINDING_DIRECTIONS),
    KERNEL(scatter, 1u << SB_ORDERS_BINDING_DENSITY | 1u << SB_ORDERS_BINDING_VIEWS)};
#undef KERNEL

struct sb_orders_settings sb_orders_product_grid(const struct sb_atmosphere_params *p)
{
    return (struct sb_orders_settings){.r = SB_ORDERS_R,
                                       .mu = sb_orders_mu_nodes(p),
                                       .mu_s = sb_orders_mu_s_nodes(p),
                                       .nu = sb_orders_nu_nodes(p),
                                       .tolerance = SB_ORDERS_TOLERANCE};
}

uint32_t sb_orders_kernels(struct sb_pipeline_params out[KERNEL_COUNT])
{
    memcpy(out, kernels, sizeof(kernels));
    return KERNEL_COUNT;
}

void sb_orders_code_hash(char out[SB_HASH_HEX_SIZE])
{
    char text[KERNEL_COUNT * SB_HASH_HEX_SIZE + 64];
    size_t n = 0;
    for (int i = 0; i < KERNEL_COUNT; i++) {
        sb_hash_bytes(kernels[i].spirv, kernels[i].spirv_size, text + n);
        n += SB_HASH_HEX_SIZE - 1;
    }
    snprintf(text + n, sizeof(text) - n, " directions %d %d %d tail %a", SB_ORDERS_DIRECTIONS_GROUND,
             SB_ORDERS_DIRECTIONS_SKY, SB_ORDERS_DIRECTIONS_PHI, SB_ORDERS_TAIL_MAX_RATIO);
    sb_hash_bytes(text, strlen(text), out);
}

/* Workgroups along z for `items` (orders.comp's first_item): one an
 * invocation on a GPU, which needs them all in flight (on the H200 the
 * scatter stage took 1.0 ms an order with one, 0.4 ms with these); one on a
 * CPU device, where every item an invocation made llvmpipe's orders 8% slower. */
static uint32_t item_groups(const struct sb_vk *vk, int items)
{
    if (vk->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU)
        return 1;
    return (uint32_t)((items + SB_ORDERS_THREADS - 1) / SB_ORDERS_THREADS);
}

static bool grid_ok(const struct sb_orders_settings *s)
{
    int n[4] = {s->r, s->mu, s->mu_s, s->nu};
    for (int i = 0; i < 4; i++)
        if (n[i] < 2 || n[i] > SB_ORDERS_MAX_NODES)
            return false;
    return (double)s->r * s->mu * s->mu_s * s->nu <= SB_ORDERS_MAX_GRID_NODES && s->mu >= 4 && s->max_order >= 2 &&
           s->max_order <= SB_ORDERS_MAX_ORDER && s->tolerance > 0 && s->tolerance < 1;
}

static float float_of(uint32_t bits)
{
    float f;
    memcpy(&f, &bits, sizeof(f));
    return f;
}

/*
 * Where the orders are computed in a delta-M scaled medium (sb_orders_medium,
 * a fraction f of Mie's scattering carried on as unscattered light), the
 * light that fraction carries forward and the air then scatters once: the
 * runtime draws single scattering in the atmosphere itself, with Mie's whole
 * phase, so the table adds, at each node, single scattering in the medium
 * (its transmittance, its smooth phase) less the same smooth scattering in
 * the atmosphere's transmittance; and on the ground row, the sun the
 * peak carries to the ground. `single`: the medium's single scattering
 * kernel's output (2 n vec4, Rayleigh's then Mie's, without their phase),
 * then the atmosphere's; out: rgb per node, then per mu_s node.
 */
static bool delta_m_light(const struct sb_atmosphere_params *p, const struct sb_atmosphere_params *medium, double f,
                          const struct sb_orders_settings *s, const float *single, double *out)
{
    struct sb_orders_ref *grid = sb_orders_grid_create(p, s);
    if (!grid)
        return false;
    size_t n = (size_t)s->r * s->mu * s->mu_s * s->nu;
    const float *scaled = single, *whole = single + 8 * n;
    for (size_t i = 0; i < n; i++) {
        double h, mu, mu_s, nu;
        sb_orders_grid_node(grid, i, &h, &mu, &mu_s, &nu);
        double pr = sb_ref_phase_rayleigh(nu), pm = sb_ref_phase_mie(medium->mie_g, nu);
        for (int c = 0; c < 3; c++) {
            double rayleigh = (double)scaled[4 * i + c] - whole[4 * i + c];
            double mie = (double)scaled[4 * (n + i) + c] - (1.0 - f) * whole[4 * (n + i) + c];
            out[3 * i + c] = fmax(pr * rayleigh + pm * mie, 0.0);
        }
    }
    for (int i = 0; i < s->mu_s; i++) {
        double mu_s = sb_orders_grid_mu_s(grid, i), t_medium[3] = {0, 0, 0}, t[3] = {0, 0, 0};
        if (mu_s > 0) {
            sb_ref_transmittance(medium, p->ground_radius_km, mu_s, 2, t_medium);
            sb_ref_transmittance(p, p->ground_radius_km, mu_s, 2, t);
        }
        for (int c = 0; c < 3; c++)
            out[3 * (n + (size_t)i) + c] = p->solar_irradiance[c] * fmax(t_medium[c] - t[c], 0.0) * fmax(mu_s, 0.0);
    }
    sb_orders_ref_destroy(&grid);
    return true;
}

enum sb_result sb_orders_bake(struct sb_vk *vk, struct sb_atmosphere_baker *baker, const struct sb_atmosphere_params *p,
                              const struct sb_orders_settings *settings, struct sb_image *image,
                              struct sb_orders_result *result)
{
    struct sb_orders_settings s = sb_orders_settings_resolve(settings);
    memset(result, 0, sizeof(*result));
    if (!grid_ok(&s)) {
        sb_error("orders: the grid must have 2 to %d nodes a dimension (mu even, at least 4), at most %d in all, and 2 "
                 "to %d "
                 "orders under a tolerance in (0, 1); got %dx%dx%dx%d, %d orders, %g",
                 SB_ORDERS_MAX_NODES, SB_ORDERS_MAX_GRID_NODES, SB_ORDERS_MAX_ORDER, s.r, s.mu, s.mu_s, s.nu,
                 s.max_order, s.tolerance);
        return SB_ERR_USAGE;
    }
    struct sb_orders_push push;
    sb_orders_grid_pack(p, s.r, s.mu, s.mu_s, s.nu, &push);
    size_t n = (size_t)s.r * s.mu * s.mu_s * s.nu, vec4 = 4 * sizeof(float);
    uint32_t sun_groups = (uint32_t)((s.mu_s + SB_ORDERS_DENSITY_SUNS - 1) / SB_ORDERS_DENSITY_SUNS);
    /* order k's radiance in previous[k % 2]: the last two orders are there
     * at the end, for the tail */
    struct sb_buffer single = {0}, previous[2] = {{0}}, density = {0}, sum = {0}, ground = {0}, stats = {0},
                     directions = {0}, views = {0}, dummy = {0}, single_whole = {0};
    struct sb_pipeline pipelines[KERNEL_COUNT] = {0};
    float *table = NULL, *last = NULL; /* the last two orders' radiance */
    /* a peaked Mie's orders in its delta-M medium, in a baker of their own */
    struct sb_atmosphere_params medium;
    double f = sb_orders_medium(p, &medium), ms = 0;
    struct sb_atmosphere_baker *scaled = NULL;
    float *singles = NULL;
    double *forward = NULL; /* delta_m_light's */
    enum sb_result res;
    if ((res = sb_image_init(image, (uint32_t)(s.mu_s * s.nu), (uint32_t)(s.r * s.mu + 1), 3)) ||
        (res = sb_buffer_create(vk, 2 * n * vec4, "orders single", &single)) ||
        (res = sb_buffer_create(vk, n * vec4, "orders previous", &previous[0])) ||
        (res = sb_buffer_create(vk, n * vec4, "orders previous", &previous[1])) ||
        (res = sb_buffer_create_texels(vk, n * vec4, "orders density", &density)) ||
        (res = sb_buffer_create(vk, n * vec4, "orders sum", &sum)) ||
        (res = sb_buffer_create(vk, (size_t)(SB_ORDERS_MAX_ORDER + 1) * s.mu_s * vec4, "orders ground", &ground)) ||
        (res = sb_buffer_create(vk, 16, "orders stats", &stats)) ||
        (res = sb_buffer_create_texels(vk, (size_t)s.r * sun_groups * SB_ORDERS_DIRECTIONS * 4 * vec4,
                                       "orders directions", &directions)) ||
        (res = sb_buffer_create_texels(vk, (size_t)s.r * s.mu * (1 + 3 * SB_ORDERS_VIEW_SAMPLES) * vec4, "orders views",
                                       &views)) ||
        (res = sb_buffer_create(vk, 16, "orders unused", &dummy)))
        goto done;
    if (f > 0) {
        struct sb_image t = {0};
        if ((res = sb_atmosphere_baker_create(vk, &medium, &scaled)) ||
            (res = sb_atmosphere_bake(scaled, SB_PRODUCT_TRANSMITTANCE, NULL, &t, NULL, &ms)) ||
            (res = sb_buffer_create(vk, 2 * n * vec4, "orders single (atmosphere)", &single_whole))) {
            sb_image_finish(&t);
            goto done;
        }
        sb_image_finish(&t);
        result->gpu_ms += ms;
    }
    sb_image_set_channel_names(image, "r,g,b");
    const struct sb_buffer *bindings[SB_ORDERS_BINDING_COUNT];
    for (int i = 0; i < SB_ORDERS_BINDING_COUNT; i++)
        bindings[i] = &dummy;
    sb_atmosphere_bind_inputs(baker, bindings);
    bindings[SB_BINDING_MULTISCATTERING] = bindings[SB_BINDING_IRRADIANCE_GROUND] = &dummy;
    bindings[SB_ORDERS_BINDING_SINGLE] = &single;
    bindings[SB_ORDERS_BINDING_PREVIOUS] = &previous[0];
    bindings[SB_ORDERS_BINDING_DENSITY] = &density;
    bindings[SB_ORDERS_BINDING_SUM] = &sum;
    bindings[SB_ORDERS_BINDING_GROUND] = &ground;
    bindings[SB_ORDERS_BINDING_STATS] = &stats;
    bindings[SB_ORDERS_BINDING_DIRECTIONS] = &directions;
    bindings[SB_ORDERS_BINDING_VIEWS] = &views;
    for (int k = 0; k < KERNEL_COUNT; k++) {
        if ((res = sb_pipeline_create(vk, &kernels[k], &pipelines[k])))
            goto done;
        sb_pipeline_bind(vk, &pipelines[k], bindings);
    }
    uint32_t node_groups = (uint32_t)((n + SB_ORDERS_THREADS - 1) / SB_ORDERS_THREADS);
    if (scaled) { /* single scattering in the atmosphere itself first, then all in the medium */
        bindings[SB_ORDERS_BINDING_SINGLE] = &single_whole;
        sb_pipeline_bind(vk, &pipelines[SINGLE], bindings);
        if ((res = sb_dispatch(vk, &pipelines[SINGLE], &push, node_groups, 1, 1, &ms)))
            goto done;
        result->gpu_ms += ms;
        sb_atmosphere_bind_inputs(scaled, bindings);
        bindings[SB_BINDING_MULTISCATTERING] = bindings[SB_BINDING_IRRADIANCE_GROUND] = &dummy;
        bindings[SB_ORDERS_BINDING_SINGLE] = &single;
        for (int k = 0; k < KERNEL_COUNT; k++)
            sb_pipeline_bind(vk, &pipelines[k], bindings);
    }
    if ((res = sb_dispatch(vk, &pipelines[SINGLE], &push, node_groups, 1, 1, &ms)))
        goto done;
    result->gpu_ms += ms;
    /* the views' samples, the same for every order */
    if ((res = sb_dispatch(vk, &pipelines[VIEWS], &push,
                           (uint32_t)((s.r * s.mu + SB_ORDERS_THREADS - 1) / SB_ORDERS_THREADS), 1, 1, &ms)))
        goto done;
    result->gpu_ms += ms;
    for (int k = 2; k <= s.max_order; k++) {
        sb_status("orders: order %d", k);
        push.order = (uint32_t)k;
        memset(stats.mapped, 0, 16);
        bindings[SB_ORDERS_BINDING_PREVIOUS] = &previous[(k - 1) % 2];
        sb_pipeline_bind(vk, &pipelines[DIRECTIONS], bindings);
        bindings[SB_ORDERS_BINDING_PREVIOUS] = &previous[k % 2];
        sb_pipeline_bind(vk, &pipelines[SCATTER], bindings);
        if ((res = sb_dispatch(vk, &pipelines[DIRECTIONS], &push, (uint32_t)s.r, sun_groups,
                               item_groups(vk, SB_ORDERS_DIRECTIONS), &ms)))
            goto done;
        result->gpu_ms += ms;
        double density_ms = ms;
        if ((res = sb_dispatch(vk, &pipelines[DENSITY], &push, (uint32_t)s.r, sun_groups, item_groups(vk, s.mu * s.nu),
                               &ms)))
            goto done;
        result->gpu_ms += ms;
        density_ms += ms;
        if ((res = sb_dispatch(vk, &pipelines[SCATTER], &push, (uint32_t)s.mu, (uint32_t)s.r,
                               item_groups(vk, s.mu_s * s.nu), &ms)))
            goto done;
        result->gpu_ms += ms;
        const uint32_t *largest = stats.mapped;
        float order_max = float_of(largest[0]), sum_max = float_of(largest[1]);
        result->orders = k;
        result->last_share = sum_max > 0 ? order_max / sum_max : 0.0;
        sb_debug("orders: order %d: largest %.4g, the sum's %.4g (share %.3g); density %.1f ms, scatter %.1f ms", k,
                 order_max, sum_max, result->last_share, density_ms, ms);
        if (!isfinite(order_max) || !isfinite(sum_max)) {
            sb_error("orders: order %d is not finite; nothing was baked", k);
            res = SB_ERR_NUMERIC;
            goto done;
        }
        if (result->last_share < s.tolerance)
            break;
    }
    if (result->last_share >= s.tolerance)
        sb_warn("orders: order %d still adds %.3g of the sum's largest value (tolerance %g)", result->orders,
                result->last_share, s.tolerance);
    /* Everything the table is made of, read back at once: the last two
     * orders, the sum and the ground's irradiance. */
    int last_order = result->orders;
    size_t ground_floats = (size_t)(SB_ORDERS_MAX_ORDER + 1) * s.mu_s * 4;
    if (!(last = malloc(2 * n * vec4)) || !(table = malloc(n * vec4 + ground_floats * sizeof(float)))) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    const struct sb_buffer *reads[] = {&previous[last_order % 2], &sum, &ground, &previous[(last_order - 1) % 2]};
    void *outs[] = {last, table, table + 4 * n, last + 4 * n};
    if ((res = sb_buffers_read(vk, last_order > 2 ? 4 : 3, reads, outs)))
        goto done;
    if (scaled) {
        const struct sb_buffer *single_reads[] = {&single, &single_whole};
        if (!(singles = malloc(4 * n * vec4)) || !(forward = malloc(3 * (n + (size_t)s.mu_s) * sizeof(double)))) {
            res = SB_ERR_NOMEM;
            goto done;
        }
        void *single_outs[] = {singles, singles + 8 * n};
        if ((res = sb_buffers_read(vk, 2, single_reads, single_outs)))
            goto done;
        if (!delta_m_light(p, &medium, f, &s, singles, forward)) {
            res = SB_ERR_NOMEM;
            goto done;
        }
    }
    /* the tail: the last order's sum over the nodes to the one's before, in the nodes' order */
    double last_sum[3] = {0, 0, 0}, before_sum[3] = {0, 0, 0};
    for (size_t i = 0; last_order > 2 && i < n; i++)
        for (int c = 0; c < 3; c++) {
            last_sum[c] += last[4 * i + c];
            before_sum[c] += last[4 * (n + i) + c];
        }
    for (int c = 0; c < 3; c++) /* 0 at order 2: no order before it */
        result->tail[c] = sb_orders_tail_factor(last_sum[c], before_sum[c]);
    sb_debug("orders: the tail after order %d: %.4g %.4g %.4g times its radiance", result->orders, result->tail[0],
             result->tail[1], result->tail[2]);
    /* the last row: the ground's irradiance from the sky, orders 1 to N - 1
     * (order j's is in the ground buffer's row j), the same at every nu */
    for (int i = 0; i < s.mu_s; i++)
        for (int c = 0; c < 3; c++) {
            double e = 0;
            for (int j = 1; j < result->orders; j++)
                e += table[4 * (n + (size_t)j * s.mu_s + i) + c];
            e += result->tail[c] * table[4 * (n + (size_t)(result->orders - 1) * s.mu_s + i) + c];
            if (forward)
                e += forward[3 * (n + (size_t)i) + c];
            for (int k = 0; k < s.nu; k++)
                image->data[3 * (n + (size_t)i * s.nu + k) + c] = (float)e;
        }
    for (size_t i = 0; i < n + (size_t)s.mu_s * s.nu; i++)
        for (int c = 0; c < 3; c++) {
            float v = i < n ? (float)(table[4 * i + c] + result->tail[c] * last[4 * i + c] +
                                      (forward ? forward[3 * i + c] : 0.0))
                            : image->data[3 * i + c];
            if (!isfinite(v) || v < 0) {
                sb_error("orders: node %zu channel %d is %g; nothing was baked", i, c, v);
                res = SB_ERR_NUMERIC;
                goto done;
            }
            image->data[3 * i + c] = v;
        }
done:
    sb_status(NULL);
    free(table);
    free(last);
    free(singles);
    free(forward);
    for (int k = 0; k < KERNEL_COUNT; k++)
        sb_pipeline_destroy(vk, &pipelines[k]);
    struct sb_buffer *buffers[] = {&single, &previous[0], &previous[1],  &density,    &sum,  &ground,
                                   &stats,  &dummy,       &single_whole, &directions, &views};
    for (size_t i = 0; i < sizeof(buffers) / sizeof(buffers[0]); i++)
        sb_buffer_destroy(vk, buffers[i]);
    sb_atmosphere_baker_destroy(&scaled);
    if (res)
        sb_image_finish(image);
    return res;
}

void sb_orders_product_sky(const struct sb_atmosphere_params *p, const struct sb_orders_ref *grid,
                           const struct sb_image *orders, const struct sb_image *transmittance, double h, double mu,
                           double mu_s, double nu, double out[3])
{
    double ms[3], e_sky[3];
    sb_ref_sky_radiance(p, h, mu, mu_s, nu, transmittance, NULL, NULL, NULL, out);
    sb_orders_table_read(grid, orders->data, h, mu, mu_s, nu, ms);
    double R = p->ground_radius_km, top = p->top_radius_km, r = R + fmax(h, 0.0);
    for (int c = 0; c < 3; c++)
        out[c] += ms[c];
    double disc = r * r * (mu * mu - 1.0) + R * R;
    if (mu >= 0.0 || disc < 0.0)
        return;
    /* the ground where the view ends, lit by the sun and by every order of the sky */
    double d = -r * mu - sqrt(disc), t_in = 0.0;
    if (r > top)
        t_in = -r * mu - sqrt(fmax(r * r * (mu * mu - 1.0) + top * top, 0.0));
    double depth[3], sun[3], mu_s_g = fmax(-1.0, fmin(1.0, (r * mu_s + d * nu) / R));
    sb_ref_optical_depth(p, r, mu, t_in, d, 2, depth);
    sb_ref_transmittance_lookup(p, transmittance, R, mu_s_g, sun);
    sb_orders_table_ground(grid, orders->data, mu_s_g, e_sky);
    for (int c = 0; c < 3; c++) {
        double direct = p->solar_irradiance[c] * sun[c] * fmax(mu_s_g, 0.0);
        out[c] += exp(-depth[c]) * p->ground_albedo[c] / M_PI * (direct + e_sky[c]);
    }
}

void sb_orders_hillaire_error(const struct sb_atmosphere_params *p, const struct sb_image baked[SB_PRODUCT_COUNT],
                              const struct sb_image *orders, double altitude_km, const double *suns_deg, int sun_count,
                              double *rms, double *worst)
{
    struct sb_orders_settings grid = sb_orders_product_grid(p);
    struct sb_orders_ref *g = sb_orders_grid_create(p, &grid);
    double sum2 = 0, largest = 0;
    int n = 0;
    for (int s = 0; g && s < sun_count; s++) {
        double hillaire[SB_SKY_ERROR_DIRECTIONS][3], exact[SB_SKY_ERROR_DIRECTIONS][3], brightest[3] = {0, 0, 0};
        for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++) {
            double zen, az, mu, mu_s, nu;
            sb_sky_error_view(p, altitude_km, d, &zen, &az);
            sb_sky_error_cosines(zen, az, suns_deg[s], &mu, &mu_s, &nu);
            const struct sb_image *t = &baked[SB_PRODUCT_TRANSMITTANCE], *ig = &baked[SB_PRODUCT_IRRADIANCE_GROUND];
            sb_ref_sky_radiance(p, altitude_km, mu, mu_s, nu, t, &baked[SB_PRODUCT_MULTISCATTERING], ig, NULL,
                                hillaire[d]);
            sb_orders_product_sky(p, g, orders, t, altitude_km, mu, mu_s, nu, exact[d]);
            for (int c = 0; c < 3; c++)
                brightest[c] = fmax(brightest[c], exact[d][c]);
        }
        for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++)
            for (int c = 0; c < 3; c++) {
                double e = (hillaire[d][c] - exact[d][c]) / fmax(exact[d][c], 1e-3 * brightest[c]);
                sum2 += e * e;
                largest = fmax(largest, fabs(e));
                n++;
            }
    }
    sb_orders_ref_destroy(&g);
    *rms = n ? sqrt(sum2 / n) : 0;
    *worst = largest;
}
