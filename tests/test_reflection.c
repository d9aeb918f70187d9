/*
 * Reflection probes (baker/reflection.h) on the device against the fp64
 * reference (reflection_ref.c), on analytic environments and on a cube
 * captured from the test world: a constant environment comes out of every
 * level exactly; a single bright texel's lobe and a half-lit sphere match
 * the dense integral; the captured cube's levels are within the issue's
 * 1% rms relative; face edges are no rougher than the faces' insides (no
 * seams); the capture sees the sky where nothing is in the way and two
 * bakes are identical. Prints the error table docs/reflections.md quotes.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "cube.h"
#include "exr.h"
#include "harness_vk.h"
#include "load.h"
#include "mesh.h"
#include "reflection.h"
#include "scene.h"

#define N 32
#define LEVELS 6 /* log2 N + 1 */

struct errors {
    double rms, max; /* relative */
    double edge_rms; /* the same over face-edge texels only */
};

/* The chain's texel value (rgb) at level l, face f, (x, y). */
static const float *texel(const float *chain, uint32_t l, int f, uint32_t x, uint32_t y)
{
    uint32_t m = N >> l;
    return chain + 4 * (sb_cube_level_offset(N, l) + (size_t)f * m * m + (size_t)y * m + x);
}

/* Device against the reference at level l over sampled texels: every
 * edge and corner texel of every face and a lattice of inside ones,
 * relative to max(reference, floor). */
static struct errors compare_level(const float *level0, const float *chain, uint32_t l, int sub, double floor_value)
{
    uint32_t m = N >> l;
    double r = sb_reflection_level_roughness(l, LEVELS);
    struct errors e = {0};
    double sum = 0, edge_sum = 0;
    int count = 0, edge_count = 0;
    uint32_t stride = m > 8 ? m / 8 : 1;
    for (int f = 0; f < 6; f++)
        for (uint32_t y = 0; y < m; y++)
            for (uint32_t x = 0; x < m; x++) {
                bool edge = x == 0 || y == 0 || x == m - 1 || y == m - 1;
                if (!edge && (x % stride || y % stride))
                    continue;
                double d[3], ref[3];
                sb_cube_texel_direction(f, m, x, y, d);
                sb_reflection_reference(level0, N, d, r, sub, ref);
                const float *got = texel(chain, l, f, x, y);
                for (int c = 0; c < 3; c++) {
                    double rel = fabs(got[c] - ref[c]) / fmax(fabs(ref[c]), floor_value);
                    e.max = fmax(e.max, rel);
                    sum += rel * rel;
                    count++;
                    if (edge) {
                        edge_sum += rel * rel;
                        edge_count++;
                    }
                }
            }
    e.rms = sqrt(sum / count);
    e.edge_rms = sqrt(edge_sum / edge_count);
    return e;
}

/* Mean |difference| of level l's texels across face edges (each edge
 * texel against the texel one step past the edge on the next face) and
 * between inside neighbours one step apart: a seam is a jump at the edges
 * that the insides do not have. */
static void seam_jumps(const float *chain, uint32_t l, double *across, double *inside)
{
    uint32_t m = N >> l;
    double a = 0, b = 0;
    int na = 0, nb = 0;
    for (int f = 0; f < 6; f++)
        for (uint32_t i = 0; i < m; i++)
            for (int side = 0; side < 4; side++) {
                uint32_t x = side == 0 ? 0 : side == 1 ? m - 1 : i, y = side == 2 ? 0 : side == 3 ? m - 1 : i;
                int dx = side == 0 ? -1 : side == 1 ? 1 : 0, dy = side == 2 ? -1 : side == 3 ? 1 : 0;
                double u = (x + 0.5 + dx) / m * 2 - 1, v = (y + 0.5 + dy) / m * 2 - 1, d[3], pu, pv;
                sb_cube_direction(f, u, v, d);
                int g = sb_cube_face(d, &pu, &pv);
                uint32_t gx = (uint32_t)fmin(fmax((pu * 0.5 + 0.5) * m, 0), m - 1);
                uint32_t gy = (uint32_t)fmin(fmax((pv * 0.5 + 0.5) * m, 0), m - 1);
                const float *p = texel(chain, l, f, x, y), *q = texel(chain, l, g, gx, gy);
                if (m > 2) {
                    const float *in = texel(chain, l, f, x - dx, y - dy);
                    for (int c = 0; c < 3; c++)
                        b += fabs(p[c] - in[c]);
                    nb += 3;
                }
                for (int c = 0; c < 3; c++)
                    a += fabs(p[c] - q[c]);
                na += 3;
            }
    *across = a / na;
    *inside = nb ? b / nb : 0;
}

static float *prefilter(struct sb_vk *vk, const float *level0, uint32_t samples)
{
    float *chain = calloc(sb_cube_level_offset(N, LEVELS) * 4, sizeof(float));
    const struct sb_prefilter_params params = {.samples = samples};
    CHECK(sb_reflection_prefilter(vk, level0, N, &params, chain, NULL) == SB_OK, "prefilter");
    return chain;
}

static void fill(float *level0, int kind)
{
    for (int f = 0; f < 6; f++)
        for (uint32_t y = 0; y < N; y++)
            for (uint32_t x = 0; x < N; x++) {
                float *t = &level0[4 * ((size_t)f * N * N + y * N + x)];
                double d[3];
                sb_cube_texel_direction(f, N, x, y, d);
                if (kind == 0) { /* constant, awkward values */
                    t[0] = 0.1f;
                    t[1] = 3.3f;
                    t[2] = 1234.5678f;
                } else if (kind == 1) { /* one bright texel beside a corner of +z, faint floor elsewhere */
                    float on = f == 4 && x == N - 2 && y == 1 ? 1000.0f : 0.01f;
                    t[0] = t[1] = t[2] = on;
                } else { /* the upper half lit */
                    t[0] = d[1] > 0 ? 1.0f : 0.05f;
                    t[1] = d[1] > 0 ? 0.8f : 0.05f;
                    t[2] = d[1] > 0 ? 0.6f : 0.05f;
                }
                t[3] = 0;
            }
}

int main(void)
{
    struct sb_vk *vk = NULL;
    enum sb_result res = test_vulkan(false, &vk);
    if (res == SB_ERR_NO_DEVICE)
        return test_no_device();
    if (res)
        return test_finish("reflection");
    const uint32_t samples = 512;
    float *level0 = malloc((size_t)6 * N * N * 4 * sizeof(float));

    /* The roughness mapping: 0 at level 0, 1 at the last, Filament's in between. */
    CHECK(sb_reflection_level_roughness(0, LEVELS) == 0 && sb_reflection_level_roughness(LEVELS - 1, LEVELS) == 1,
          "roughness ends");
    for (uint32_t l = 1; l < LEVELS; l++) {
        double r = sb_reflection_level_roughness(l, LEVELS), t = (double)l / (LEVELS - 1);
        CHECK(fabs(r * (2 - r) - t) < 1e-12, "level %u: r (2 - r) = %g, not %g", l, r * (2 - r), t);
    }

    /* A constant environment: every texel of every level, exactly. */
    fill(level0, 0);
    float *chain = prefilter(vk, level0, samples);
    uint64_t inexact = 0;
    for (uint64_t t = 0; t < sb_cube_level_offset(N, LEVELS); t++)
        inexact += chain[4 * t] != 0.1f || chain[4 * t + 1] != 3.3f || chain[4 * t + 2] != 1234.5678f;
    CHECK(inexact == 0, "constant environment: %llu texels differ from it", (unsigned long long)inexact);
    free(chain);

    /* One bright texel and a half-lit sphere against the dense integral: the
     * bright texel's lobe relative to its peak (filtered importance sampling
     * reads it from box-filtered levels, so its shape, not its every texel,
     * is what holds), the sphere relative to each texel. */
    static const char *const names[] = {"", "bright texel", "half-lit sphere"};
    static const double rms_bound[] = {0, 0.02, 0.01};
    for (int kind = 1; kind <= 2; kind++) {
        fill(level0, kind);
        chain = prefilter(vk, level0, samples);
        for (uint32_t l = 1; l < LEVELS; l++) {
            double floor_value = 1e-3;
            if (kind == 1) {
                double at[3], peak[3];
                sb_cube_texel_direction(4, N, N - 2, 1, at);
                sb_reflection_reference(level0, N, at, sb_reflection_level_roughness(l, LEVELS), 4, peak);
                floor_value = peak[0];
            }
            struct errors e = compare_level(level0, chain, l, 4, floor_value);
            double across, inside;
            seam_jumps(chain, l, &across, &inside);
            printf("%-16s level %u (r %.3f): rms %.2e max %.2e, edges rms %.2e; jump across edges %.3g, inside %.3g\n",
                   names[kind], l, sb_reflection_level_roughness(l, LEVELS), e.rms, e.max, e.edge_rms, across, inside);
            /* A delta's lobe at r >= 0.5 is read by about one sample at
             * level 0 (the lod for a wide lobe's sample density is below
             * 0): noisy there, stated in docs/reflections.md, not checked. */
            if (kind == 2 || sb_reflection_level_roughness(l, LEVELS) < 0.5)
                CHECK(e.rms <= rms_bound[kind], "%s, level %u: rms %.3g over %.3g", names[kind], l, e.rms,
                      rms_bound[kind]);
        }
        free(chain);
    }

    /* A cube captured from the test world: the prefilter within 1% rms relative at every level, the edges no worse
     * than the rest and no rougher across than inside. */
    struct sb_scene scene;
    res = sb_scene_load(SOURCE_ROOT "/data/scenes/earth.json", &scene);
    CHECK(res == SB_OK, "the earth scene");
    struct sb_atmosphere_baker *atm = NULL;
    struct sb_image luts[3] = {{0}};
    static const enum sb_product_id ids[3] = {SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_MULTISCATTERING,
                                              SB_PRODUCT_IRRADIANCE_GROUND};
    CHECK(sb_atmosphere_baker_create(vk, &scene.atmosphere, &atm) == SB_OK, "atmosphere");
    for (int i = 0; i < 3 && atm; i++)
        CHECK(sb_atmosphere_bake(atm, ids[i], NULL, &luts[i], NULL, NULL) == SB_OK, "%s", sb_product_name(ids[i]));
    struct sb_mesh mesh = {0};
    struct sb_bvh bvh = {0};
    struct sb_raycaster *rc = NULL;
    CHECK(sb_mesh_load(SOURCE_ROOT "/data/worlds/test.json", NULL, &mesh) == SB_OK, "test world");
    struct sb_surfaces surfaces = {0};
    CHECK(sb_bvh_build(&mesh, &bvh) == SB_OK && sb_raycaster_create(vk, &bvh, &rc) == SB_OK &&
              sb_surfaces_create(vk, &mesh, 1, &surfaces) == SB_OK,
          "bvh");
    struct sb_capture_params cp = {
        .origin_m = {0, 1.5f, -20}, .altitude_km = 1.5e-3, .face_size = N, .ambient_rays = 32};
    double el = 30 * M_PI / 180, az = 150 * M_PI / 180;
    cp.sun[0] = cos(el) * sin(az);
    cp.sun[1] = sin(el);
    cp.sun[2] = -cos(el) * cos(az);
    float *sky = malloc((size_t)6 * N * N * 4 * sizeof(float)), *again = malloc((size_t)6 * N * N * 4 * sizeof(float));
    struct sb_capture_inputs sky_in = {.atmosphere = atm};
    struct sb_capture_inputs world_in = {
        .atmosphere = atm, .rc = rc, .surfaces = &surfaces};
    CHECK(sb_reflection_capture(vk, &sky_in, &cp, sky, NULL, NULL) == SB_OK, "sky capture");
    sb_reflection_sh(sky, N, 0, cp.sky_sh);
    CHECK(sb_reflection_capture(vk, &world_in, &cp, level0, NULL, NULL) == SB_OK, "world capture");
    /* Seen from 100 m up, nothing is above: the +y face is the sky's own
     * capture there, bit for bit; from 1.5 m, the -y face is all ground. */
    struct sb_capture_params high = cp;
    high.origin_m[1] = 100;
    high.altitude_km = 0.1;
    CHECK(sb_reflection_capture(vk, &sky_in, &high, sky, NULL, NULL) == SB_OK, "sky capture, high");
    CHECK(sb_reflection_capture(vk, &world_in, &high, again, NULL, NULL) == SB_OK, "world capture, high");
    CHECK(!memcmp(sky + 4 * 2 * N * N, again + 4 * 2 * N * N, (size_t)N * N * 4 * sizeof(float)),
          "+y from 100 m: the world's capture is not the sky's");
    int down_ground = 0;
    for (uint32_t t = 0; t < N * N; t++)
        down_ground += level0[4 * (3 * N * N + t)] != sky[4 * (3 * N * N + t)];
    CHECK(down_ground == N * N, "-y: %d of %d texels see the ground", down_ground, N * N);
    CHECK(sb_reflection_capture(vk, &world_in, &cp, again, NULL, NULL) == SB_OK, "world capture again");
    CHECK(!memcmp(level0, again, (size_t)6 * N * N * 4 * sizeof(float)), "two captures differ");
    int finite = 1;
    for (size_t t = 0; t < (size_t)6 * N * N * 4; t++)
        finite &= isfinite(level0[t]) && level0[t] >= 0;
    CHECK(finite, "the capture holds a negative or non-finite value");
    /* 1024 ambient rays a surface, cast in 16 passes (config.h: each
     * invocation at most 64 casts, under lavapipe's loop limit), against
     * 32 in one: the same light but for the quadrature, over the -y face
     * (all ground). */
    {
        struct sb_capture_params many = cp;
        many.ambient_rays = 1024;
        CHECK(sb_reflection_capture(vk, &world_in, &many, again, NULL, NULL) == SB_OK, "world capture, 1024 ambient rays");
        double sum_a = 0, sum_b = 0;
        for (size_t t = (size_t)3 * N * N; t < (size_t)4 * N * N; t++) {
            sum_a += level0[4 * t] + level0[4 * t + 1] + level0[4 * t + 2];
            sum_b += again[4 * t] + again[4 * t + 1] + again[4 * t + 2];
        }
        printf("capture with 1024 ambient rays a surface: the ground below %.4f of its light with 32\n",
               sum_b / sum_a);
        CHECK(fabs(sum_b / sum_a - 1) < 0.02, "1024 ambient rays: %.4f of 32's light", sum_b / sum_a);
    }

    /* The capture reads a surface's albedo from its texture: over a floor
     * black where x < 0 and white where x > 0, the -y face is black (0)
     * where it sees the black half and, where it sees the white half, the
     * same floor untextured (albedo 1) bit for bit; near the seam, where a
     * texel's footprint spans both, in between. */
    {
        struct sb_mesh floors[2] = {{0}, {0}};
        struct sb_mesh_texture t = {.name = "halves", .width = 64, .height = 64, .srgb = 1};
        t.rgba = malloc(sb_texture_bytes(&t));
        for (uint32_t i = 0; i < 64 * 64; i++)
            for (int c = 0; c < 4; c++)
                t.rgba[4 * i + c] = c == 3 || i % 64 >= 32 ? 255 : 0;
        for (int f = 0; f < 2; f++) {
            uint32_t m, tex;
            sb_mesh_add_material(&floors[f], "floor", (double[3]){1, 1, 1}, &m);
            if (f == 0) {
                sb_mesh_add_texture(&floors[0], &t, &tex);
                floors[0].material_list[m].textures[SB_TEXTURE_BASE_COLOR] = (int32_t)tex;
            }
            double p[4][3] = {{-20, 0, 20}, {20, 0, 20}, {20, 0, -20}, {-20, 0, -20}};
            const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            const int tris[2][3] = {{0, 1, 2}, {0, 2, 3}};
            for (int k = 0; k < 2; k++) {
                float tuv[3][2];
                for (int j = 0; j < 3; j++)
                    memcpy(tuv[j], uv[tris[k][j]], sizeof(tuv[j]));
                sb_mesh_add_textured_triangle(&floors[f], p[tris[k][0]], p[tris[k][1]], p[tris[k][2]], tuv, NULL, m,
                                              "floor");
            }
        }
        float *seen[2] = {malloc((size_t)6 * N * N * 4 * sizeof(float)), malloc((size_t)6 * N * N * 4 * sizeof(float))};
        struct sb_capture_params over = cp;
        over.origin_m[0] = 0;
        over.origin_m[2] = 0;
        for (int f = 0; f < 2; f++) {
            struct sb_bvh fb = {0};
            struct sb_raycaster *frc = NULL;
            struct sb_surfaces fs = {0};
            CHECK(sb_bvh_build(&floors[f], &fb) == SB_OK && sb_raycaster_create(vk, &fb, &frc) == SB_OK &&
                      sb_surfaces_create(vk, &floors[f], 1, &fs) == SB_OK,
                  "floor %d", f);
            struct sb_capture_inputs in = {.atmosphere = atm, .rc = frc, .surfaces = &fs};
            CHECK(sb_reflection_capture(vk, &in, &over, seen[f], NULL, NULL) == SB_OK, "capture over floor %d", f);
            sb_surfaces_destroy(vk, &fs);
            sb_raycaster_destroy(&frc);
            sb_bvh_finish(&fb);
            sb_mesh_finish(&floors[f]);
        }
        int black = 0, white = 0, between = 0, wrong = 0;
        for (uint32_t y = 0; y < N; y++)
            for (uint32_t x = 0; x < N; x++) {
                double d[3];
                sb_cube_texel_direction(3, N, x, y, d); /* -y */
                double at_x = 1.5 * d[0] / -d[1];      /* where the ray meets the floor */
                const float *a = &seen[0][4 * (3 * N * N + y * N + x)], *b = &seen[1][4 * (3 * N * N + y * N + x)];
                if (at_x < -0.5) { /* a texel (0.625 m) from the seam: bilinear reaches it no further */
                    black++;
                    wrong += a[0] != 0 || a[1] != 0 || a[2] != 0;
                } else if (at_x > 0.5) {
                    white++;
                    wrong += memcmp(a, b, 3 * sizeof(float)) != 0;
                } else {
                    between++;
                    wrong += !(a[1] >= 0 && a[1] <= b[1]);
                }
            }
        printf("capture over a floor textured half black, half white: %d texels black, %d as the untextured floor, "
               "%d at the seam within them; %d otherwise\n",
               black, white, between, wrong);
        CHECK(wrong == 0 && black > N * N / 4 && white > N * N / 4, "the capture's textured floor: %d texels wrong",
              wrong);
        free(seen[0]);
        free(seen[1]);
    }

    chain = prefilter(vk, level0, samples);
    float *chain2 = prefilter(vk, level0, samples);
    CHECK(!memcmp(chain, chain2, sb_cube_level_offset(N, LEVELS) * 4 * sizeof(float)), "two prefilters differ");
    free(chain2);
    for (uint32_t l = 1; l < LEVELS; l++) {
        struct errors e = compare_level(level0, chain, l, 4, 1e-6);
        double across, inside;
        seam_jumps(chain, l, &across, &inside);
        printf("test world       level %u (r %.3f): rms %.2e max %.2e, edges rms %.2e; jump across edges %.3g, inside "
               "%.3g\n",
               l, sb_reflection_level_roughness(l, LEVELS), e.rms, e.max, e.edge_rms, across, inside);
        CHECK(e.rms <= 0.01, "test world, level %u: rms %.3g over 1%%", l, e.rms);
        CHECK(e.edge_rms <= 2 * e.rms + 1e-3, "test world, level %u: edges rms %.3g against %.3g overall", l,
              e.edge_rms, e.rms);
        if (l + 2 < LEVELS) /* faces of 2 texels and fewer have no inside */
            CHECK(across <= 2 * inside, "test world, level %u: a seam (jump %.3g across edges, %.3g inside)", l, across,
                  inside);
    }
    free(chain);
    free(sky);
    free(again);
    free(level0);
    for (int i = 0; i < 3; i++)
        sb_image_finish(&luts[i]);
    sb_surfaces_destroy(vk, &surfaces);
    sb_raycaster_destroy(&rc);
    sb_bvh_finish(&bvh);
    sb_mesh_finish(&mesh);
    sb_atmosphere_baker_destroy(&atm);
    CHECK(sb_vk_validation_messages(vk) == 0, "%u validation messages", sb_vk_validation_messages(vk));
    sb_vk_destroy(&vk);
    return test_finish("reflection");
}
