/* Cloud noise (baker/clouds.h): the GPU bake against the CPU reference, bit
 * for bit; exact and statistical tiling across every wrap seam; values in
 * [0, 1] with histograms that are not degenerate; the same bits twice. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "clouds.h"
#include "harness_vk.h"
#include "image.h"
#include "log.h"

static uint64_t texels(const struct sb_image *v)
{
    return (uint64_t)v->width * v->height * v->depth;
}

static float at(const struct sb_image *v, uint32_t x, uint32_t y, uint32_t z, uint32_t c)
{
    return v->data[(((uint64_t)z * v->height + y) * v->width + x) * v->channel_count + c];
}

/* The GPU's values against the reference's, every `stride`-th texel. */
static void check_reference(const char *name, const struct sb_noise_push *pc, const struct sb_image *v, uint64_t stride)
{
    uint64_t n = texels(v), compared = 0, differ = 0;
    uint32_t worst_ulps = 0;
    float ref[SB_NOISE_MAX_CHANNELS];
    for (uint64_t t = 0; t < n; t += stride) {
        sb_cloud_ref(pc, t, 1, ref);
        for (uint32_t c = 0; c < v->channel_count; c++) {
            float g = v->data[t * v->channel_count + c];
            compared++;
            if (memcmp(&g, &ref[c], sizeof(g)) != 0) {
                differ++;
                int32_t a, b;
                memcpy(&a, &g, 4);
                memcpy(&b, &ref[c], 4);
                uint32_t ulps = (uint32_t)abs(a - b);
                worst_ulps = ulps > worst_ulps ? ulps : worst_ulps;
            }
        }
    }
    printf("%s: %llu values against the CPU reference, %llu differ (at most %u ulps)\n", name,
           (unsigned long long)compared, (unsigned long long)differ, worst_ulps);
    CHECK(differ == 0, "%s: %llu of %llu values differ from the CPU reference, by up to %u ulps", name,
          (unsigned long long)differ, (unsigned long long)compared, worst_ulps);
}

/* Range and histogram: every value in [0, 1]; mean in [0.15, 0.85], standard
 * deviation at least 0.04, and no more than 20% of the values at 0 or 1. */
static void check_range(const char *name, const struct sb_image *v)
{
    uint64_t n = texels(v);
    for (uint32_t c = 0; c < v->channel_count; c++) {
        double sum = 0, sum2 = 0;
        uint64_t outside = 0, ends = 0;
        for (uint64_t t = 0; t < n; t++) {
            double x = v->data[t * v->channel_count + c];
            outside += !(x >= 0 && x <= 1);
            ends += x == 0 || x == 1;
            sum += x;
            sum2 += x * x;
        }
        double mean = sum / (double)n, sd = sqrt(fmax(sum2 / (double)n - mean * mean, 0));
        printf("%s channel %u: mean %.3f, sd %.3f, %.2f%% at 0 or 1\n", name, c, mean, sd,
               100.0 * (double)ends / (double)n);
        CHECK(outside == 0, "%s channel %u: %llu values outside [0, 1]", name, c, (unsigned long long)outside);
        CHECK(mean >= 0.15 && mean <= 0.85 && sd >= 0.04, "%s channel %u: mean %.3f, sd %.3f", name, c, mean, sd);
        CHECK(ends <= n / 5, "%s channel %u: %.1f%% of the values clamped", name, c, 100.0 * (double)ends / (double)n);
    }
}

/*
 * Tiling. Statistically: across each wrap seam (texel N-1 to texel 0) the
 * values jump as they do between interior neighbours at the same place in
 * the lattice: the seam lies on a boundary of every octave's cells, and so
 * do the interior steps onto a multiple of the coarsest cell (N / 4
 * texels; the fade makes Perlin flatter there). The seam's mean absolute
 * jump is within 50% of theirs. (Jumps along a plane are correlated over
 * the cells, so standard errors from their count would be far too small.
 * A seam that does not tile jumps by about the values' spread: the test
 * checks that a broken seam, texel N-1 against texel N/2, falls outside
 * the band, above 1.5 times the interior's jump, for every channel.)
 * Exactly: with power-of-two sizes and periods the texel one period on
 * (index N) is computed exactly and equals texel 0 bit for bit (`exact`;
 * with other sizes 1/N is rounded and the coordinates one period on differ
 * in their last bits). Every period must be a multiple of 4.
 */
static void check_tiling(const char *name, const struct sb_noise_push *pc, const struct sb_image *v, bool exact)
{
    uint32_t size[3] = {v->width, v->height, v->depth};
    double worst = 0, broken_least = INFINITY;
    for (int axis = 0; axis < 3; axis++) {
        if (size[axis] == 1)
            continue;
        uint32_t cell = size[axis] / 4;
        for (uint32_t c = 0; c < v->channel_count; c++) {
            double seam = 0, inner = 0, broken = 0;
            uint64_t seams = 0, inners = 0;
            for (uint32_t z = 0; z < v->depth; z++)
                for (uint32_t y = 0; y < v->height; y++)
                    for (uint32_t x = 0; x < v->width; x++) {
                        uint32_t p[3] = {x, y, z}, q[3] = {x, y, z};
                        q[axis] = (p[axis] + 1) % size[axis];
                        if (q[axis] % cell != 0)
                            continue;
                        double jump = fabs(at(v, p[0], p[1], p[2], c) - at(v, q[0], q[1], q[2], c));
                        if (q[axis] == 0) {
                            seam += jump;
                            seams++;
                            q[axis] = size[axis] / 2;
                            broken += fabs(at(v, p[0], p[1], p[2], c) - at(v, q[0], q[1], q[2], c));
                        } else {
                            inner += jump;
                            inners++;
                        }
                    }
            double mean = inner / (double)inners, seam_mean = seam / (double)seams;
            worst = fmax(worst, fabs(seam_mean / mean - 1));
            broken_least = fmin(broken_least, broken / (double)seams / mean);
            CHECK(broken / (double)seams > 1.5 * mean,
                  "%s channel %u axis %d: a broken seam jumps only %.3g x the interior: inside the band, untestable",
                  name, c, axis, broken / (double)seams / mean);
            CHECK(fabs(seam_mean - mean) <= 0.5 * mean,
                  "%s channel %u axis %d: mean jump across the seam %.4g, across interior cell boundaries %.4g", name,
                  c, axis, seam_mean, mean);
        }
        if (!exact)
            continue;
        /* Exact: texel N along this axis against texel 0, over a line of texels. */
        struct sb_noise_push shifted = *pc;
        uint32_t *sizes[3] = {&shifted.size_x, &shifted.size_y, &shifted.size_z};
        *sizes[axis] += 1;
        uint64_t mismatched = 0;
        float wrapped[SB_NOISE_MAX_CHANNELS], origin[SB_NOISE_MAX_CHANNELS];
        for (uint32_t i = 0; i < size[(axis + 1) % 3]; i++) {
            uint32_t idx[3] = {0, 0, 0};
            idx[(axis + 1) % 3] = i;
            idx[axis] = size[axis];
            uint64_t t = ((uint64_t)idx[2] * shifted.size_y + idx[1]) * shifted.size_x + idx[0];
            sb_cloud_ref(&shifted, t, 1, wrapped);
            idx[axis] = 0;
            t = ((uint64_t)idx[2] * shifted.size_y + idx[1]) * shifted.size_x + idx[0];
            sb_cloud_ref(&shifted, t, 1, origin);
            mismatched += memcmp(wrapped, origin, v->channel_count * sizeof(float)) != 0;
        }
        CHECK(mismatched == 0, "%s axis %d: %llu texels one period on differ from their wrap", name, axis,
              (unsigned long long)mismatched);
    }
    printf("%s: seams jump within %.0f%% of interior cell boundaries (a broken seam: %.1f x or more)%s\n", name,
           100 * worst, broken_least, exact ? "; one period on is bit-identical" : "");
}

static void quiet(void *user, enum sb_log_level level, const char *msg)
{
    (void)user;
    if (level <= SB_LOG_WARN)
        fprintf(stderr, "%s\n", msg);
}

int main(void)
{
    sb_log_set_sink(quiet, NULL);
    struct sb_vk *vk;
    enum sb_result res = test_vulkan(false, &vk);
    if (res == SB_ERR_NO_DEVICE)
        return test_no_device();
    if (res)
        return test_finish("clouds");

    /* The defaults (power-of-two sizes), and sizes, periods, cells,
     * octaves and a seed of a scene's own choosing. */
    struct sb_cloud_params defaults, custom = {
                                         .seed = 99,
                                         .shape_size = 96,
                                         .shape_perlin = {4, 3},
                                         .shape_worley_cells = {4, 12, 8},
                                         .detail_size = 40,
                                         .detail_worley_cells = {4, 8, 4},
                                         .curl_size = 100,
                                         .curl = {4, 3},
                                         .weather_size = 200,
                                         .coverage = {4, 5},
                                         .precipitation = {8, 4},
                                         .cloud_type = {4, 2},
                                     };
    sb_cloud_params_default(&defaults);
    CHECK(sb_cloud_params_validate(&custom, "custom") == SB_OK, "the custom parameters are valid");
    for (int set = 0; set < 2; set++) {
        const struct sb_cloud_params *cp = set ? &custom : &defaults;
        for (int p = SB_PRODUCT_CLOUD_SHAPE; p <= SB_PRODUCT_WEATHER; p++) {
            enum sb_product_id product = (enum sb_product_id)p;
            char name[64];
            snprintf(name, sizeof(name), "%s%s", sb_product_name(product), set ? " (custom)" : "");
            struct sb_noise_push pc;
            sb_cloud_recipe(product, cp, &pc);
            struct sb_image v, again;
            double ms = 0;
            res = sb_cloud_bake(vk, product, cp, &v, &ms);
            CHECK(res == SB_OK, "%s: %s", name, sb_result_name(res));
            if (res)
                continue;
            printf("%s: %ux%ux%u x%u baked in %.1f ms\n", name, v.width, v.height, v.depth, v.channel_count, ms);
            /* The largest volume is compared at every 61st texel (a prime:
             * every position in the lattice cells comes up); the others
             * everywhere. */
            check_reference(name, &pc, &v, product == SB_PRODUCT_CLOUD_SHAPE ? 61 : 1);
            check_range(name, &v);
            check_tiling(name, &pc, &v, !set);
            if (!set)
                CHECK(sb_cloud_bake(vk, product, cp, &again, &ms) == SB_OK &&
                          !memcmp(v.data, again.data, texels(&v) * v.channel_count * sizeof(float)),
                      "%s: a second bake differs", name);
            if (!set)
                sb_image_finish(&again);
            sb_image_finish(&v);
        }
    }
    struct sb_cloud_params cp = defaults;
    /* Another seed, another texture. */
    struct sb_image a, b;
    double ms;
    cp.seed = 1;
    CHECK(sb_cloud_bake(vk, SB_PRODUCT_CLOUD_DETAIL, &cp, &b, &ms) == SB_OK, "detail, seed 1");
    cp.seed = 0;
    CHECK(sb_cloud_bake(vk, SB_PRODUCT_CLOUD_DETAIL, &cp, &a, &ms) == SB_OK, "detail, seed 0");
    CHECK(a.data && b.data && memcmp(a.data, b.data, texels(&a) * a.channel_count * sizeof(float)) != 0,
          "the seed changes the noise");
    sb_image_finish(&a);
    sb_image_finish(&b);

    CHECK(sb_vk_validation_messages(vk) == 0, "%u validation messages", sb_vk_validation_messages(vk));
    sb_vk_destroy(&vk);
    return test_finish("clouds");
}
