/*
 * skyview's volumetric clouds on the Vulkan device (validation on): a pack
 * with the cloud noise baked here, a flat ground, small frames.
 * - The clouds at a handful of pixels against an fp64 march of the same
 *   density field and lighting model (cloud_layer_ref.c), at converged
 *   settings and at the defaults.
 * - The clouds' shadow on the ground against the fp64 optical depth.
 * - A moved camera's reprojected clouds against a fresh frame's.
 * - Extremes (inside, above and far above the layer, the sun below the
 *   horizon, an overcast of dense cloud) render finite frames.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "cloud_layer_ref.h"
#include "config.h"
#include "harness_view.h"
#include "harness_vk.h"
#include "log.h"
#include "pack.h"
#include "parallel.h"
#include "renderer.h"
#include "scene.h"
#include "transform.h"
#include "world.h"

#define DEG (M_PI / 180.0)
#define W 96
#define H 64
#define PICKS 6

static struct sb_vk *vk;
static struct sb_pack pack;
static struct sb_world world;

static double luminance(const double *rgb)
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

static struct sb_view base_view(void)
{
    return (struct sb_view){
        .camera_m = {0.0, 2.0, 0.0},
        .pitch = 40.0 * DEG,
        .fov_y = 60.0 * DEG,
        .sun_azimuth = 150.0 * DEG,
        .sun_elevation = 35.0 * DEG,
    };
}

/* The last of `frames` frames (the first a cut) of a renderer made with
 * `rp`, at `v` and then, if given, once at `then`; NULL on failure. */
static float *frames_at(const struct sb_pack *p, const struct sb_renderer_params *rp, const struct sb_view *v,
                        int frames, const struct sb_view *then)
{
    struct sb_renderer *r = NULL;
    float *rgb = NULL;
    if (sb_renderer_create(vk, p, &world, rp, &r) != SB_OK) {
        CHECK(false, "the clouds' renderer");
        return NULL;
    }
    bool ok = true;
    for (int i = 0; i < frames && ok; i++) {
        struct sb_view f = *v;
        f.snap_exposure = i == 0;
        ok = sb_renderer_render(r, &f, i == frames - 1 && !then, NULL) == SB_OK;
    }
    if (ok && then)
        ok = sb_renderer_render(r, then, true, NULL) == SB_OK;
    CHECK(ok, "render the clouds");
    if (ok) {
        rgb = malloc(sizeof(float) * 3 * W * H);
        sb_renderer_hdr(r, rgb);
    }
    sb_renderer_destroy(&r);
    return rgb;
}

/* The world ray through pixel (x, y)'s centre, as the renderer makes it. */
static void pixel_ray(const struct sb_view *v, double x, double y, double d[3])
{
    double forward[3], up[3] = {0, 1, 0};
    sb_direction(v->yaw, v->pitch, forward);
    struct sb_mat4 view = sb_mat4_look(forward, up);
    struct sb_mat4 proj = sb_mat4_perspective(v->fov_y, (double)W / H, 0.1);
    struct sb_mat4 vp = sb_mat4_mul(&proj, &view);
    struct sb_mat4 inv = sb_mat4_inverse(&vp);
    double ndc[3] = {(x + 0.5) / W * 2.0 - 1.0, (y + 0.5) / H * 2.0 - 1.0, 0.5}, p[3];
    sb_mat4_project(&inv, ndc, p);
    double n = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int k = 0; k < 3; k++)
        d[k] = p[k] / n;
}

static void ref_setup(struct sb_cloud_ref *ref, const struct sb_scene *scene, const struct sb_view *v)
{
    memset(ref, 0, sizeof(*ref));
    ref->atmosphere = &scene->atmosphere;
    ref->transmittance = &pack.images[SB_PRODUCT_TRANSMITTANCE];
    static const enum sb_product_id noise[4] = {SB_PRODUCT_CLOUD_SHAPE, SB_PRODUCT_CLOUD_DETAIL, SB_PRODUCT_CLOUD_CURL,
                                                SB_PRODUCT_WEATHER};
    for (int i = 0; i < 4; i++)
        ref->noise[i] = &pack.images[noise[i]];
    ref->layer = scene->cloud_layer;
    memcpy(ref->camera_m, v->camera_m, sizeof(ref->camera_m));
    sb_direction(v->sun_azimuth, v->sun_elevation, ref->sun);
    sb_cloud_ref_init(ref, &pack.images[SB_PRODUCT_MULTISCATTERING]);
}

struct pick_job {
    const struct sb_cloud_ref *ref;
    const struct sb_view *view;
    int x[PICKS], y[PICKS];
    double S[PICKS][3], T[PICKS];
};

static void march_pick(void *user, int i)
{
    struct pick_job *job = user;
    double d[3];
    pixel_ray(job->view, job->x[i], job->y[i], d);
    sb_cloud_ref_march(job->ref, d, 1e30, job->S[i], &job->T[i]);
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The clouds' in-scattering and transmittance at PICKS pixels of a sky
 * view against the fp64 march: pixels spread over the range of the
 * frame's transmittance (0.05 to 0.95), so thin and thick cloud are both
 * there. Returns the worst relative error of in-scattering's luminance and
 * the worst absolute error of transmittance. */
static void against_reference(const struct sb_pack *p, const struct sb_scene *scene,
                              const struct sb_renderer_params *settings, int frames, double *worst_s, double *worst_t)
{
    struct sb_view v = base_view();
    struct sb_renderer_params rp = *settings;
    rp.debug = SB_DEBUG_CLOUDS;
    float *S = frames_at(p, &rp, &v, frames, NULL);
    rp.debug = SB_DEBUG_CLOUD_TRANSMITTANCE;
    float *T = frames_at(p, &rp, &v, frames, NULL);
    *worst_s = *worst_t = INFINITY;
    if (!S || !T)
        goto done;
    /* Candidates on a grid, sorted by transmittance; PICKS spread over those in (0.05, 0.95). */
    double keys[(W / 8) * (H / 8)];
    int count = 0;
    for (int y = 4; y < H; y += 8)
        for (int x = 4; x < W; x += 8) {
            float t = T[3 * (y * W + x)];
            if (t > 0.05f && t < 0.95f)
                keys[count++] = t + 1e-6 * (y * W + x) / (W * H); /* ties broken by place */
        }
    CHECK(count >= PICKS, "the reference view has %d cloudy pixels of %d; it needs %d", count, (W / 8) * (H / 8),
          PICKS);
    if (count < PICKS)
        goto done;
    qsort(keys, (size_t)count, sizeof(double), compare_doubles);
    struct sb_cloud_ref ref;
    ref_setup(&ref, scene, &v);
    struct pick_job job = {.ref = &ref, .view = &v};
    for (int i = 0; i < PICKS; i++) {
        double key = keys[(i * (count - 1)) / (PICKS - 1)];
        for (int y = 4; y < H; y += 8)
            for (int x = 4; x < W; x += 8)
                if (fabs(T[3 * (y * W + x)] + 1e-6 * (y * W + x) / (W * H) - key) < 1e-9) {
                    job.x[i] = x;
                    job.y[i] = y;
                }
    }
    sb_parallel_for(PICKS, march_pick, &job);
    *worst_s = *worst_t = 0.0;
    for (int i = 0; i < PICKS; i++) {
        const float *s = S + 3 * (job.y[i] * W + job.x[i]);
        double got[3] = {s[0], s[1], s[2]};
        double e_s = fabs(luminance(got) - luminance(job.S[i])) / luminance(job.S[i]);
        double e_t = fabs(T[3 * (job.y[i] * W + job.x[i])] - job.T[i]);
        printf("  pixel (%2d, %2d): in-scattering %.4g (fp64 %.4g, %.2e), transmittance %.4f (fp64 %.4f)\n", job.x[i],
               job.y[i], luminance(got), luminance(job.S[i]), e_s, T[3 * (job.y[i] * W + job.x[i])], job.T[i]);
        *worst_s = fmax(*worst_s, e_s);
        *worst_t = fmax(*worst_t, e_t);
    }
done:
    free(S);
    free(T);
}

static void test_reference(const struct sb_pack *p, const struct sb_scene *scene)
{
    /* Converged settings: every pixel traced every frame, fine steps; 32
     * frames average the jitter (history weight 0.8). What remains: the
     * jitter's noise (a few 1e-3), the light march's 16 pieces against
     * 512, fp16 frames, the irradiance LUT against its reference (1e-3). */
    struct sb_renderer_params fine = {.width = W,
                                      .height = H,
                                      .cloud_scale = 1,
                                      .cloud_steps = 1024,
                                      .cloud_light_steps = 16,
                                      .cloud_shadow_size = 64};
    double s, t;
    against_reference(p, scene, &fine, 32, &s, &t);
    CHECK(s < 2e-2 && t < 2e-3,
          "converged clouds: in-scattering %.2e (at most 2e-2), transmittance %.2e (2e-3) off "
          "the fp64 march",
          s, t);
    printf("clouds, converged settings: in-scattering %.2e, transmittance %.2e off the fp64 march\n", s, t);

    /* skyview's defaults: one pixel in 2 x 2 a frame, 128 steps, 6 light
     * steps growing linearly. Their error is mostly the light march's six
     * pieces over up to 4 km of noise (the optical depth toward the sun,
     * jittered but under-resolved), then the view march's 20 m steps. */
    struct sb_renderer_params defaults = {.width = W, .height = H, .cloud_shadow_size = 64};
    against_reference(p, scene, &defaults, 32, &s, &t);
    CHECK(s < 0.12 && t < 1e-2,
          "default clouds: in-scattering %.2e (at most 0.12), transmittance %.2e (1e-2) off "
          "the fp64 march",
          s, t);
    printf("clouds, default settings: in-scattering %.2e, transmittance %.2e off the fp64 march\n", s, t);
}

/* The clouds' shadow on the ground seen from 400 m up, to 8 km away, against the fp64
 * optical depth along the sun's ray from each ground point. */
static void test_shadow(const struct sb_pack *p, const struct sb_scene *scene)
{
    struct sb_view v = base_view();
    v.camera_m[1] = 400.0;
    v.pitch = -25.0 * DEG;
    v.fov_y = 80.0 * DEG;
    struct sb_renderer_params rp = {.width = W, .height = H, .debug = SB_DEBUG_CLOUD_SHADOW};
    float *rgb = frames_at(p, &rp, &v, 1, NULL);
    if (!rgb)
        return;
    struct sb_cloud_ref ref;
    ref_setup(&ref, scene, &v);
    double sum = 0, worst = 0, lo = 1, hi = 0;
    int n = 0;
    for (int y = 2; y < H; y += 4)
        for (int x = 2; x < W; x += 4) {
            double d[3];
            pixel_ray(&v, x, y, d);
            if (d[1] > -0.05)
                continue;
            double t = -v.camera_m[1] / d[1];
            double g[3] = {v.camera_m[0] + d[0] * t, 0.0, v.camera_m[2] + d[2] * t};
            double want = sb_cloud_ref_sun_transmittance(&ref, g), got = rgb[3 * (y * W + x)];
            sum += fabs(got - want);
            worst = fmax(worst, fabs(got - want));
            lo = fmin(lo, want);
            hi = fmax(hi, want);
            n++;
        }
    /* The view must cross shade and sun, or the comparison proves little. */
    CHECK(n > 100 && hi - lo > 0.3, "the shadow view: %d ground pixels, transmittance %.3f to %.3f", n, lo, hi);
    /* 32 midpoint pieces a texel, fp16; the worst where a shadow's edge
     * crosses a 31 m texel read bilinearly. */
    CHECK(sum / n < 2e-3 && worst < 0.15,
          "cloud shadow: mean %.2e (at most 2e-3), worst %.2e (0.15) off the fp64 "
          "optical depth",
          sum / n, worst);
    printf("cloud shadow: %d ground points, transmittance %.2f to %.2f; mean %.2e, worst %.2e off fp64\n", n, lo, hi,
           sum / n, worst);
    free(rgb);
}

/* Mean |luminance difference| of two frames over the second's mean luminance. */
static double frame_difference(const float *a, const float *b)
{
    double diff = 0, sum = 0;
    for (int i = 0; i < W * H; i++) {
        double x[3] = {a[3 * i], a[3 * i + 1], a[3 * i + 2]}, y[3] = {b[3 * i], b[3 * i + 1], b[3 * i + 2]};
        diff += fabs(luminance(x) - luminance(y));
        sum += luminance(y);
    }
    return diff / fmax(sum, 1e-30);
}

/* After 16 frames at one place, the camera moves 20 m and turns 4 degrees
 * (6 pixels); the next frame, three quarters of it reprojected history,
 * against a fresh one's 16th there. Two yardsticks: the frame before the
 * move (what a history kept in place, the ghost, would show) and the first
 * frame of a fresh renderer there (what dropping the history would show). */
static void test_reprojection(const struct sb_pack *p)
{
    struct sb_view v = base_view();
    struct sb_view moved = v;
    moved.camera_m[0] += 20.0;
    moved.yaw += 4.0 * DEG;
    struct sb_renderer_params rp = {.width = W, .height = H, .cloud_shadow_size = 64, .debug = SB_DEBUG_CLOUDS};
    float *kept = frames_at(p, &rp, &v, 16, &moved);
    float *fresh = frames_at(p, &rp, &moved, 16, NULL);
    float *stale = frames_at(p, &rp, &v, 16, NULL);
    float *first = frames_at(p, &rp, &moved, 1, NULL);
    if (kept && fresh && stale && first) {
        double d_kept = frame_difference(kept, fresh), d_stale = frame_difference(stale, fresh);
        double d_first = frame_difference(first, fresh);
        CHECK(d_kept < 0.25 * d_stale && d_kept < d_first,
              "the moved camera's clouds: %.2e off a fresh frame's; the frame before the move %.2e (at most a "
              "quarter of it), a first frame %.2e (less than it)",
              d_kept, d_stale, d_first);
        printf("clouds: a moved camera's reprojected frame %.2e off a converged one; unmoved history %.2e, no "
               "history %.2e\n",
               d_kept, d_stale, d_first);
    } else {
        CHECK(false, "the reprojection frames");
    }
    free(kept);
    free(fresh);
    free(stale);
    free(first);
}

/* Pre-exposure: the clouds' history rescaled (harness_view.h), over eight
 * frames (two rounds of the 2 x 2 reconstruction). */
static void test_pre_exposure(const struct sb_pack *p)
{
    struct sb_view v = base_view();
    struct sb_renderer_params rp = {.width = W, .height = H, .cloud_shadow_size = 64, .debug = SB_DEBUG_CLOUDS};
    test_history_rescaled(vk, p, &world, &rp, &v, 8, "the clouds'");
}

/* Every value of the lit frame finite and not negative. */
static void test_extremes(const struct sb_pack *p, struct sb_scene *scene)
{
    static const struct {
        const char *what;
        double height_m, pitch_deg, sun_deg;
        bool dense;
    } cases[] = {
        {"the camera inside the layer", 2500.0, 0.0, 35.0, false},
        {"the camera inside a dense overcast", 2500.0, 10.0, 35.0, true},
        {"the camera above the layer", 6000.0, -30.0, 35.0, false},
        {"the camera in orbit", 500e3, -60.0, 35.0, false},
        {"the sun below the horizon", 2.0, 20.0, -10.0, false},
        {"the sun at the nadir", 2.0, 20.0, -90.0, false},
        {"the sun at the zenith over a dense overcast", 2.0, 20.0, 90.0, true},
    };
    struct sb_cloud_layer_params saved = scene->cloud_layer;
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        scene->cloud_layer = saved;
        if (cases[i].dense) {
            scene->cloud_layer.coverage = 1.0;
            scene->cloud_layer.extinction_per_m = 1.0;
        }
        struct sb_view v = base_view();
        v.camera_m[1] = cases[i].height_m;
        v.pitch = cases[i].pitch_deg * DEG;
        v.sun_elevation = cases[i].sun_deg * DEG;
        struct sb_renderer_params rp = {.width = W, .height = H, .cloud_shadow_size = 64};
        float *rgb = frames_at(p, &rp, &v, 3, NULL);
        if (!rgb)
            continue;
        int bad = 0;
        for (int k = 0; k < 3 * W * H; k++)
            bad += !(isfinite(rgb[k]) && rgb[k] >= 0.0f);
        CHECK(bad == 0, "%s: %d values negative, NaN or Inf", cases[i].what, bad);
        free(rgb);
    }
    scene->cloud_layer = saved;
}

int main(void)
{
    enum sb_result res = test_vulkan(true, &vk);
    if (res == SB_ERR_NO_DEVICE)
        return test_no_device();
    if (res)
        return test_finish("cloud layer");
    char dir[256];
    CHECK(test_temp_dir("skyview-clouds", dir, sizeof(dir)), "temporary directory");
    char pack_dir[300], world_path[300];
    snprintf(pack_dir, sizeof(pack_dir), "%s/pack", dir);
    snprintf(world_path, sizeof(world_path), "%s/ground.json", dir);

    /* What skyview's clouds read: the atmosphere and the cloud noise. */
    struct sb_scene scene = {.name = "clouds test", .preset = "earth"};
    sb_atmosphere_preset_earth(&scene.atmosphere);
    sb_cloud_params_default(&scene.clouds);
    static const enum sb_product_id wanted[] = {SB_PRODUCT_IRRADIANCE_GROUND, SB_PRODUCT_CLOUD_SHAPE,
                                                SB_PRODUCT_CLOUD_DETAIL, SB_PRODUCT_CLOUD_CURL, SB_PRODUCT_WEATHER};
    for (size_t i = 0; i < sizeof(wanted) / sizeof(wanted[0]); i++)
        scene.wants[wanted[i]] = true;
    struct sb_bake_report report;
    CHECK(sb_bake_scene(vk, &scene, pack_dir, NULL, &report) == SB_OK, "bake");
    CHECK(sb_pack_open(pack_dir, &pack) == SB_OK, "the pack opens");
    FILE *f = fopen(world_path, "w");
    if (f) {
        fputs("{\"version\": 1, \"ground\": {\"size_m\": 20000, \"albedo\": [0.2, 0.2, 0.2]}}\n", f);
        CHECK(fclose(f) == 0, "write %s", world_path);
    }
    CHECK(sb_world_load(world_path, NULL, &world) == SB_OK, "the world loads");

    if (pack.scene && world.vertices) {
        /* The layer skyview draws by default, over the camera's sky. */
        struct sb_scene layer_scene = *pack.scene;
        struct sb_pack p = pack;
        p.scene = &layer_scene;
        layer_scene.has_cloud_layer = true;
        sb_cloud_layer_params_default(&layer_scene.cloud_layer);
        test_reference(&p, &layer_scene);
        layer_scene.cloud_layer.coverage = 0.5;
        test_shadow(&p, &layer_scene);
        layer_scene.cloud_layer.coverage = 0.4;
        test_reprojection(&p);
        test_pre_exposure(&p);
        test_extremes(&p, &layer_scene);
    }

    CHECK(sb_vk_validation_messages(vk) == 0, "%u validation messages", sb_vk_validation_messages(vk));
    sb_vk_destroy(&vk);
    sb_world_finish(&world);
    sb_pack_close(&pack);
    CHECK(test_remove_dir(dir), "clean up");
    return test_finish("cloud layer");
}
