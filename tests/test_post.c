/*
 * skyview's post-processing passes on the Vulkan device (validation on),
 * each against the frame rendered without it, through an fp64 model of
 * what it must do:
 * - the colour science of grading (runtime/grading.c, passes/grade_linear.c) against published
 *   values: the Planckian locus, D65, Rec.709's luminance row, the
 *   Rec.709-to-AP1 matrix; white balance making its white neutral;
 * - scene-linear grading (white balance, saturation, contrast) and a LUT in
 *   ACEScct, on the HDR frame, value by value;
 * - a LUT on the display-referred frame, byte by byte;
 * - the Purkinje shift (runtime/passes/purkinje.c): nothing where the light is
 *   photopic, the model's shift where it is not.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "colour.h"
#include "harness_view.h"
#include "harness_vk.h"
#include "log.h"
#include "lut3d.h"
#include "pack.h"
#include "renderer.h"
#include "scene.h"
#include "world.h"

#define DEG (M_PI / 180.0)
#define W 160
#define H 90
#define PIXELS (W * H)

static struct sb_vk *vk;
static struct sb_pack pack;
static struct sb_world world;

static struct sb_view view_at(double sun_elevation_deg)
{
    return (struct sb_view){
        .camera_m = {0.0, 2.0, 0.0},
        .pitch = 3.0 * DEG,
        .fov_y = 50.0 * DEG,
        .sun_azimuth = 150.0 * DEG,
        .sun_elevation = sun_elevation_deg * DEG,
        .snap_exposure = true,
    };
}

/* One frame read back: 8-bit sRGB, the post-processed HDR frame in the pack's
 * units, the exposure state. */
struct frame {
    uint8_t ldr[PIXELS * 4];
    float hdr[PIXELS * 3];
    float exposure[4];
    double stored_scale; /* what the frame's halves hold the pack's radiance times */
};

static const struct sb_renderer_params base_params = {.width = W, .height = H, .shadow_size = 512};

static bool render(const struct sb_renderer_params *p, const struct sb_view *v, struct frame *f, const char *what)
{
    struct sb_renderer *r = NULL;
    enum sb_result res = sb_renderer_create(vk, &pack, &world, p, &r);
    if (!res)
        res = sb_renderer_render(r, v, true, NULL);
    CHECK(res == SB_OK, "%s: %s", what, sb_result_name(res));
    if (!res) {
        memcpy(f->ldr, sb_renderer_ldr(r), sizeof(f->ldr));
        sb_renderer_post_hdr(r, f->hdr);
        sb_renderer_exposure(r, f->exposure);
        f->stored_scale = sb_renderer_stored_scale(r);
    }
    sb_renderer_destroy(&r);
    return res == SB_OK;
}

static double luminance(const double c[3])
{
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

static void apply3(const double m[3][3], const double v[3], double out[3])
{
    double t[3];
    for (int i = 0; i < 3; i++)
        t[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
    memcpy(out, t, sizeof(t));
}

/* The HDR frame holds halves of the radiance times the frame's stored scale
 * (sb_renderer_stored_scale; pre-exposure): errors are measured in units in the last place of the half that
 * holds the wanted value (2^-24 among the subnormals). */
static double half_ulps(double got, double want, double stored_scale)
{
    double v = fabs(want) * stored_scale;
    double ulp = v < 0x1p-14 ? 0x1p-24 : exp2(floor(log2(v)) - 10.0);
    return fabs(got - want) * stored_scale / ulp;
}

struct worst {
    double ulps;
    int pixel;
};

static void record(struct worst *w, const float *got, const double want[3], int pixel, double stored_scale)
{
    for (int c = 0; c < 3; c++) {
        double e = half_ulps(got[c], want[c], stored_scale);
        if (!(e <= w->ulps)) {
            w->ulps = e;
            w->pixel = pixel;
        }
    }
}

/* ---- Colour science ------------------------------------------------------------------ */

/* The inverse of m by its cofactors. */
static void invert3(const double m[3][3], double out[3][3])
{
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int a = (j + 1) % 3, b = (j + 2) % 3, c = (i + 1) % 3, d = (i + 2) % 3;
            out[i][j] = (m[a][c] * m[b][d] - m[a][d] * m[b][c]) / det;
        }
}

static void xyz_to_rec709(const double xy[2], double rgb[3])
{
    double to_xyz[3][3], from_xyz[3][3];
    sb_rec709_to_xyz(to_xyz);
    invert3(to_xyz, from_xyz);
    double xyz[3] = {xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1]};
    apply3(from_xyz, xyz, rgb);
}

static void xy_to_uv(double x, double y, double uv[2])
{
    double d = -2.0 * x + 12.0 * y + 3.0;
    uv[0] = 4.0 * x / d;
    uv[1] = 6.0 * y / d;
}

static void test_colour_science(void)
{
    /* The Planckian locus in CIE 1960 uv, which Krystek's approximation
     * follows to about 1e-4: illuminant A (a Planckian radiator at 2856 K)
     * and the locus at 4000 K and 6500 K as tables of it give them to five
     * places, which adds up to 3e-5 (measured 5.4e-5 to 1.2e-4 off). */
    static const struct {
        double k, x, y;
    } locus[] = {{2856, 0.44757, 0.40745}, {4000, 0.38052, 0.37674}, {6500, 0.31352, 0.32363}};
    for (size_t i = 0; i < sizeof(locus) / sizeof(locus[0]); i++) {
        double xy[2], uv[2], want[2];
        sb_planckian_xy(locus[i].k, xy);
        xy_to_uv(xy[0], xy[1], uv);
        xy_to_uv(locus[i].x, locus[i].y, want);
        double d = hypot(uv[0] - want[0], uv[1] - want[1]);
        CHECK(d < 1.5e-4, "the Planckian locus at %.0f K: xy (%.5f, %.5f), %.2g in uv from (%.5f, %.5f)", locus[i].k,
              xy[0], xy[1], d, locus[i].x, locus[i].y);
    }
    double d65[2];
    sb_grading_white(SB_GRADING_NEUTRAL_K, 0.0, d65);
    CHECK(fabs(d65[0] - 0.3127) < 1e-4 && fabs(d65[1] - 0.3290) < 1e-4, "6504 K, no tint, is D65: (%.5f, %.5f)", d65[0],
          d65[1]);
    double m[3][3];
    sb_rec709_to_xyz(m);
    CHECK(fabs(m[1][0] - 0.2126) < 5e-5 && fabs(m[1][1] - 0.7152) < 5e-5 && fabs(m[1][2] - 0.0722) < 5e-5,
          "BT.709's luminance row: %.7f %.7f %.7f", m[1][0], m[1][1], m[1][2]);
    /* Rec.709 (D65) to AP1 (D60) by Bradford, as colour science libraries
     * publish it to seven places. */
    static const double ap1[3][3] = {
        {0.6130974, 0.3395231, 0.0473795}, {0.0701937, 0.9163539, 0.0134524}, {0.0206156, 0.1095698, 0.8698147}};
    sb_rec709_to_ap1(m);
    double worst = 0.0;
    for (int i = 0; i < 9; i++)
        worst = fmax(worst, fabs(m[i / 3][i % 3] - ap1[i / 3][i % 3]));
    CHECK(worst < 1e-6, "Rec.709 to AP1 differs from the published matrix by %.2g", worst);

    /* White balance at K renders K's white neutral, whatever the tint. */
    static const double kelvins[] = {1500, 2000, 3200, 5000, 6504, 9000, 15000}, tints[] = {-10, 0, 7};
    worst = 0.0;
    for (size_t i = 0; i < sizeof(kelvins) / sizeof(kelvins[0]); i++)
        for (size_t t = 0; t < 3; t++) {
            struct sb_grading g = {true, kelvins[i], tints[t], 1.0, 1.0};
            double white[2], rgb[3];
            sb_grading_white(kelvins[i], tints[t], white);
            xyz_to_rec709(white, rgb);
            sb_grading_matrix(&g, m);
            apply3(m, rgb, rgb);
            double mean = (rgb[0] + rgb[1] + rgb[2]) / 3.0;
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(rgb[c] / mean - 1.0));
        }
    CHECK(worst < 1e-12, "white balance leaves its white off grey by %.2g", worst);
    double warm[2], cool[2];
    sb_grading_white(3200, 0, warm);
    sb_grading_white(9000, 0, cool);
    CHECK(warm[0] > d65[0] && cool[0] < d65[0], "3200 K is redder than D65 and 9000 K bluer");
    double magenta[2];
    sb_grading_white(SB_GRADING_NEUTRAL_K, 10, magenta);
    CHECK(magenta[1] < d65[1], "a positive tint is a more magenta light: y %.4f below D65's", magenta[1]);

    /* Saturation 0 makes every row the luminance row; 1 and 6504 K change nothing. */
    struct sb_grading grey = {true, SB_GRADING_NEUTRAL_K, 0.0, 0.0, 1.0};
    sb_grading_matrix(&grey, m);
    double off_row = 0.0;
    for (int j = 0; j < 3; j++)
        off_row = fmax(off_row, fmax(fabs(m[0][j] - m[1][j]), fabs(m[2][j] - m[1][j])));
    /* the same row times the same white balance, so exactly */
    CHECK(off_row == 0.0, "saturation 0: rows differ by %.2g", off_row);
    struct sb_grading neutral = {true, SB_GRADING_NEUTRAL_K, 0.0, 1.0, 1.0};
    CHECK(sb_grading_is_neutral(&neutral) && !sb_grading_is_neutral(&grey), "neutral is neutral, grey is not");
}

/* ---- Scene-linear grading -------------------------------------------------------------- */

static void test_linear_grading(void)
{
    struct sb_view v = view_at(30.0);
    struct frame *off = malloc(sizeof(*off)), *on = malloc(sizeof(*on));
    if (!render(&base_params, &v, off, "the ungraded frame"))
        goto done;
    struct sb_renderer_params p = base_params;
    p.grading = (struct sb_grading){true, SB_GRADING_NEUTRAL_K, 0.0, 1.0, 1.0};
    if (render(&p, &v, on, "neutral grading"))
        CHECK(!memcmp(on->ldr, off->ldr, sizeof(on->ldr)), "neutral grading leaves every byte as it was");

    p.grading = (struct sb_grading){true, 3200.0, 3.0, 1.3, 1.25};
    if (!render(&p, &v, on, "graded"))
        goto done;
    CHECK(on->exposure[1] == off->exposure[1], "grading after the meter: the same exposure, %g and %g", on->exposure[1],
          off->exposure[1]);
    double m[3][3];
    sb_grading_matrix(&p.grading, m);
    double e = off->exposure[1];
    struct worst w = {0};
    for (int i = 0; i < PIXELS; i++) {
        double c[3] = {off->hdr[3 * i] * e, off->hdr[3 * i + 1] * e, off->hdr[3 * i + 2] * e};
        apply3(m, c, c);
        for (int k = 0; k < 3; k++)
            c[k] = 0.18 * pow(fmax(c[k], 0.0) / 0.18, p.grading.contrast) / e;
        record(&w, on->hdr + 3 * i, c, i, on->stored_scale);
    }
    /* rounding to a half, which an image store may do toward zero (< 1 ulp),
     * and fp32 arithmetic (~1e-3 ulp) */
    CHECK(w.ulps < 1.01,
          "white balance 3200 K, tint 3, saturation 1.3, contrast 1.25: %.3g half ulps off the fp64 model "
          "at pixel %d",
          w.ulps, w.pixel);
    printf("linear grading: %.3g half ulps off the fp64 model at worst (bound 1.01)\n", w.ulps);
done:
    free(off);
    free(on);
}

/* ---- LUTs ------------------------------------------------------------------------------- */

/* A LUT of n^3 entries, each f(node) for the node's (r, g, b) in [0, 1]. */
static bool make_lut(uint32_t n, void (*f)(const float in[3], float out[3]), struct sb_lut3d *lut)
{
    *lut = (struct sb_lut3d){.size = n, .domain_max = {1, 1, 1}};
    lut->rgb = malloc((size_t)n * n * n * 3 * sizeof(float));
    for (uint32_t i = 0; lut->rgb && i < n * n * n; i++) {
        const float in[3] = {(float)(i % n) / (float)(n - 1), (float)(i / n % n) / (float)(n - 1),
                             (float)(i / (n * n)) / (float)(n - 1)};
        f(in, lut->rgb + 3 * i);
    }
    return lut->rgb != NULL;
}

static void lut_neutral(const float in[3], float out[3])
{
    memcpy(out, in, 3 * sizeof(float));
}

static void lut_invert(const float in[3], float out[3])
{
    for (int c = 0; c < 3; c++)
        out[c] = 1.0f - in[c];
}

static void lut_swap(const float in[3], float out[3])
{
    out[0] = in[2];
    out[1] = in[1];
    out[2] = in[0];
}

#define LIFT 0.05 /* in ACEScct: 0.876 EV */
static void lut_lift(const float in[3], float out[3])
{
    for (int c = 0; c < 3; c++)
        out[c] = in[c] + (float)LIFT;
}

/*
 * A LUT on the display-referred frame against the ungraded frame, code by
 * code. LUTs linear in their input are reproduced exactly by trilinear
 * interpolation, so: the neutral 33^3 LUT leaves every byte as it was;
 * 1 - v at 17^3 turns each colour code q into 255 - q; swapping red and
 * blue at 2^3 swaps the codes. The frame has enough distinct codes for that
 * to mean something.
 */
static void test_display_lut(void)
{
    struct sb_view v = view_at(30.0);
    struct frame *ref = malloc(sizeof(*ref)), *f = malloc(sizeof(*f));
    if (!render(&base_params, &v, ref, "the ungraded frame"))
        goto done;
    bool seen[256] = {false};
    int distinct = 0;
    for (size_t i = 0; i < sizeof(ref->ldr); i++)
        if (i % 4 != 3 && !seen[ref->ldr[i]]) {
            seen[ref->ldr[i]] = true;
            distinct++;
        }
    CHECK(distinct >= 64, "the ungraded frame has %d distinct codes", distinct);
    static const struct {
        uint32_t size;
        void (*f)(const float in[3], float out[3]);
        const char *name;
    } luts[] = {{33, lut_neutral, "neutral"}, {17, lut_invert, "inverting"}, {2, lut_swap, "red-blue swapping"}};
    for (size_t k = 0; k < sizeof(luts) / sizeof(luts[0]); k++) {
        struct sb_lut3d lut;
        struct sb_renderer_params p = base_params;
        p.grade = &lut;
        if (make_lut(luts[k].size, luts[k].f, &lut) && render(&p, &v, f, luts[k].name)) {
            size_t wrong = 0;
            for (size_t i = 0; i < sizeof(f->ldr); i += 4)
                for (int c = 0; c < 4; c++) {
                    uint8_t q = ref->ldr[i + (k == 2 && c != 1 && c != 3 ? 2 - c : c)];
                    uint8_t want = k == 1 && c != 3 ? (uint8_t)(255 - q) : q;
                    wrong += f->ldr[i + c] != want;
                }
            CHECK(wrong == 0, "the %s LUT: %zu of %zu bytes are not what it maps the ungraded frame's to", luts[k].name,
                  wrong, sizeof(f->ldr));
        }
        sb_lut3d_finish(&lut);
    }
done:
    free(ref);
    free(f);
}

static double acescct_encode(double x)
{
    return x <= 0.0078125 ? 10.5402377416545 * x + 0.0729055341958355 : (log2(x) + 9.72) / 17.52;
}

static double acescct_decode(double y)
{
    return y <= 0.155251141552511 ? (y - 0.0729055341958355) / 10.5402377416545 : exp2(fmin(y, 1.468) * 17.52 - 9.72);
}

/*
 * A LUT in ACEScct (--grade-space acescct), on the HDR frame against the
 * fp64 round trip: Rec.709 to AP1, ACEScct, the LUT's domain [0, 1], back.
 * The neutral LUT is the identity up to that clamp (exposed AP1 values
 * above 222) and fp32; a lift of 0.05 (0.876 EV) is reproduced as the
 * model gives it. The 8-bit frame of the neutral LUT is the ungraded one
 * within a code.
 */
static void test_log_lut(void)
{
    struct sb_view v = view_at(30.0);
    struct frame *off = malloc(sizeof(*off)), *on = malloc(sizeof(*on));
    if (!render(&base_params, &v, off, "the ungraded frame"))
        goto done;
    double to_ap1[3][3], from_ap1[3][3];
    sb_rec709_to_ap1(to_ap1);
    invert3(to_ap1, from_ap1);
    static const struct {
        uint32_t size;
        void (*f)(const float in[3], float out[3]);
        double lift;
        const char *name;
    } luts[] = {{33, lut_neutral, 0.0, "neutral"}, {17, lut_lift, LIFT, "lifting"}};
    for (size_t k = 0; k < 2; k++) {
        struct sb_lut3d lut;
        struct sb_renderer_params p = base_params;
        p.grade = &lut;
        p.grade_log = true;
        if (!make_lut(luts[k].size, luts[k].f, &lut) || !render(&p, &v, on, luts[k].name)) {
            sb_lut3d_finish(&lut);
            continue;
        }
        sb_lut3d_finish(&lut);
        double e = off->exposure[1];
        struct worst w = {0};
        for (int i = 0; i < PIXELS; i++) {
            double c[3] = {off->hdr[3 * i] * e, off->hdr[3 * i + 1] * e, off->hdr[3 * i + 2] * e};
            apply3(to_ap1, c, c);
            for (int j = 0; j < 3; j++)
                c[j] = acescct_decode(fmin(fmax(acescct_encode(c[j]), 0.0), 1.0) + luts[k].lift);
            apply3(from_ap1, c, c);
            for (int j = 0; j < 3; j++)
                c[j] /= e;
            record(&w, on->hdr + 3 * i, c, i, on->stored_scale);
        }
        /* rounding to a half (< 1 ulp) and fp32 log2 and exp2 (~1e-2 ulp) */
        CHECK(w.ulps < 1.01, "the %s LUT in ACEScct: %.3g half ulps off the fp64 model at pixel %d", luts[k].name,
              w.ulps, w.pixel);
        printf("%s LUT in ACEScct: %.3g half ulps off the fp64 model at worst (bound 1.01)\n", luts[k].name, w.ulps);
        if (k == 0) {
            int worst = 0, changed = 0;
            for (size_t i = 0; i < sizeof(on->ldr); i++) {
                int d = abs((int)on->ldr[i] - (int)off->ldr[i]);
                worst = d > worst ? d : worst;
                changed += d != 0;
            }
            CHECK(worst <= 1, "the neutral LUT in ACEScct moves a code by %d", worst);
            printf("neutral LUT in ACEScct: %d of %zu codes move, by 1\n", changed, sizeof(on->ldr));
        }
    }
done:
    free(off);
    free(on);
}

/* ---- Local tone mapping ----------------------------------------------------------------- */

static double mean_log2_luminance(const float *hdr, int y0, int y1)
{
    double sum = 0.0;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < W; x++) {
            const float *p = hdr + 3 * (y * W + x);
            sum += log2(0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
        }
    return sum / ((double)(y1 - y0) * W);
}

/* The mean of |log2 Y| between horizontal neighbours: a checker's amplitude. */
static double mean_step(const float *hdr, int y0, int y1)
{
    double sum = 0.0;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x + 1 < W; x++) {
            const float *p = hdr + 3 * (y * W + x), *q = p + 3;
            sum += fabs(log2((0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) /
                             (0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2])));
        }
    return sum / ((double)(y1 - y0) * (W - 1));
}

/*
 * Local tone mapping (runtime/passes/local_tonemap.c) on images given to the post
 * chain (params.post_input):
 * - a frame of one colour, at three levels, is left bit for bit as it was
 *   (the base layer is an exact 0 there);
 * - a frame whose upper half is 4 EV brighter than its lower, each half a
 *   checker of +-0.25 EV: at contrast 0.5 the halves' interiors end 2 EV
 *   apart, each moved 1 EV toward the pivot, the checker kept.
 */
static void test_local_tonemap(void)
{
    struct sb_view v = view_at(30.0);
    struct frame *off = malloc(sizeof(*off)), *on = malloc(sizeof(*on));
    float *input = malloc(sizeof(float) * PIXELS * 3);
    struct sb_renderer_params p = base_params, q = base_params;
    p.post_input = q.post_input = input;
    q.local_contrast = 0.5;
    static const float levels[] = {1e-4f, 0.05f, 3.0f};
    for (int k = 0; k < 3; k++) {
        for (int i = 0; i < PIXELS * 3; i++)
            input[i] = levels[k] * (i % 3 == 2 ? 1.5f : 1.0f);
        if (render(&p, &v, off, "a constant frame") && render(&q, &v, on, "locally tone mapped"))
            CHECK(!memcmp(on->hdr, off->hdr, sizeof(on->hdr)) && !memcmp(on->ldr, off->ldr, sizeof(on->ldr)),
                  "local tone mapping changes a frame of one colour (%g)", levels[k]);
    }

    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++)
                input[3 * (y * W + x) + c] =
                    (float)(0.01 * (y < H / 2 ? 16.0 : 1.0) * exp2((x + y) % 2 ? 0.25 : -0.25));
    if (render(&p, &v, off, "two halves") && render(&q, &v, on, "two halves, locally tone mapped")) {
        /* interiors: 3 cells (5 pixels each) from the edge between the halves */
        int top = H / 2 - 15, bottom = H / 2 + 15;
        double in_top = mean_log2_luminance(off->hdr, 0, top), in_bottom = mean_log2_luminance(off->hdr, bottom, H);
        double out_top = mean_log2_luminance(on->hdr, 0, top), out_bottom = mean_log2_luminance(on->hdr, bottom, H);
        double step_in = mean_step(off->hdr, 0, top), step_out = mean_step(on->hdr, 0, top);
        printf("local tone mapping: halves %.3f EV apart -> %.3f (top %+.3f EV, bottom %+.3f); checker %.4f -> %.4f "
               "EV\n",
               in_top - in_bottom, out_top - out_bottom, out_top - in_top, out_bottom - in_bottom, step_in, step_out);
        /* The base is each half's mean within the fixed point's 1/64 EV and
         * the halves' rounding (measured 0.010 EV at most): 0.03. The
         * checker's phases, 0.5 EV apart, read the base at their own bins,
         * which the [1 2 1] blur makes nearly alike (measured 0.1%): 2%. */
        CHECK(fabs((out_top - out_bottom) - 0.5 * (in_top - in_bottom)) < 0.03,
              "halves %.3f EV apart end %.3f EV apart, not half", in_top - in_bottom, out_top - out_bottom);
        CHECK(fabs(out_top - in_top + 1.0) < 0.03 && fabs(out_bottom - in_bottom - 1.0) < 0.03,
              "the halves move %+.3f and %+.3f EV, not -1 and +1", out_top - in_top, out_bottom - in_bottom);
        CHECK(fabs(step_out / step_in - 1.0) < 0.02, "the checker's steps go from %.3f to %.3f EV", step_in, step_out);
    }

    /* The grid summed with a subgroup adding its pixels of a cell and bin
     * first (where the device's subgroups can) and by an atomic a pixel:
     * the same integers, so the same frame bit for bit, on the world's
     * own frame (many cells and bins). */
    struct sb_renderer_params world_params = base_params;
    world_params.local_contrast = 0.7;
    VkSubgroupFeatureFlags ops = vk->compute_subgroup_ops;
    printf("local tone mapping: this device's subgroups %s\n",
           (ops & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) && (ops & VK_SUBGROUP_FEATURE_BALLOT_BIT)
               ? "add, so both grids are compared"
               : "cannot add: one grid, compared with itself");
    if (render(&world_params, &v, on, "the world, locally tone mapped")) {
        vk->compute_subgroup_ops = 0;
        bool ok = render(&world_params, &v, off, "the world, locally tone mapped without subgroups");
        vk->compute_subgroup_ops = ops;
        CHECK(ok && !memcmp(on->hdr, off->hdr, sizeof(on->hdr)) && !memcmp(on->ldr, off->ldr, sizeof(on->ldr)),
              "the local tone mapping's grid by subgroups and by pixels give different frames");
    }
    free(input);
    free(off);
    free(on);
}

/* ---- The Purkinje shift ---------------------------------------------------------------- */

#define SUN_LUX 128000.0

/* purkinje.comp's model in fp64, for a colour in cd/m^2; the shift added. */
static void purkinje_model(const double c[3], double out[3])
{
    double y = luminance(c);
    memcpy(out, c, 3 * sizeof(double));
    if (!(y < 5.0))
        return;
    double weight = fmin(log2(5.0 / fmax(y, 1e-30)) / log2(5.0 / 0.005), 1.0);
    static const double lmsr[4][3] = {{0.31670331, 0.70299344, 0.08120592},
                                      {0.10129085, 0.72118661, 0.12041039},
                                      {0.01451538, 0.05643031, 0.53416779},
                                      {0.01724063, 0.60147464, 0.40056206}};
    static const double back[3][3] = {{4.57829597, -4.48749114, 0.31554848},
                                      {-0.63342362, 2.03236026, -0.36183302},
                                      {-0.05749394, -0.09275939, 1.90172089}};
    double q[4], g[3];
    for (int i = 0; i < 4; i++)
        q[i] = lmsr[i][0] * fmax(c[0], 0.0) + lmsr[i][1] * fmax(c[1], 0.0) + lmsr[i][2] * fmax(c[2], 0.0);
    for (int i = 0; i < 3; i++)
        g[i] = 1.0 / sqrt(1.0 + q[i]);
    for (int i = 0; i < 3; i++)
        out[i] += weight * q[3] * (back[i][0] * g[0] + back[i][1] * g[1] + back[i][2] * g[2]);
}

/*
 * Daylight is photopic everywhere in the test world: the shift leaves the
 * frame exactly as it was. At dusk and night, the HDR frame is the fp64
 * model's shift of the frame without it, and bluer.
 */
static void test_purkinje(void)
{
    const double *sun = pack.scene->atmosphere.solar_irradiance;
    double to_cd = SUN_LUX / luminance(sun); /* cd/m^2 per unit of the pack's radiance */
    struct frame *off = malloc(sizeof(*off)), *on = malloc(sizeof(*on));
    struct sb_renderer_params p = base_params;
    p.purkinje = true;
    static const double elevations[] = {30.0, -6.0, -9.0};
    for (size_t k = 0; k < 3; k++) {
        struct sb_view v = view_at(elevations[k]);
        if (!render(&base_params, &v, off, "without the shift") || !render(&p, &v, on, "with it"))
            break;
        int dim = 0;
        double blue_off = 0.0, blue_on = 0.0;
        struct worst w = {0};
        for (int i = 0; i < PIXELS; i++) {
            double c[3];
            for (int j = 0; j < 3; j++)
                c[j] = off->hdr[3 * i + j] * to_cd;
            dim += luminance(c) < 5.0;
            purkinje_model(c, c);
            for (int j = 0; j < 3; j++)
                c[j] /= to_cd;
            record(&w, on->hdr + 3 * i, c, i, on->stored_scale);
            const float *a = off->hdr + 3 * i, *b = on->hdr + 3 * i;
            blue_off += a[2] / fmax(a[0] + a[1] + a[2], 1e-30);
            blue_on += b[2] / fmax(b[0] + b[1] + b[2], 1e-30);
        }
        CHECK(w.ulps < 1.01, "sun at %g deg: the shift is %.3g half ulps off the fp64 model at pixel %d", elevations[k],
              w.ulps, w.pixel);
        printf("Purkinje, sun at %g deg: %d of %d pixels below 5 cd/m^2; %.3g half ulps off the fp64 model at worst; "
               "blue share %.3f -> %.3f\n",
               elevations[k], dim, PIXELS, w.ulps, blue_off / PIXELS, blue_on / PIXELS);
        if (k == 0) {
            CHECK(dim == 0, "daylight: %d pixels below 5 cd/m^2", dim);
            CHECK(!memcmp(on->ldr, off->ldr, sizeof(on->ldr)) && !memcmp(on->hdr, off->hdr, sizeof(on->hdr)),
                  "daylight: the shift changes the frame");
        } else {
            CHECK(dim > PIXELS / 2, "sun at %g deg: only %d pixels below 5 cd/m^2", elevations[k], dim);
            CHECK(blue_on > blue_off + 0.01 * PIXELS, "sun at %g deg: the blue share goes from %.3f only to %.3f",
                  elevations[k], blue_off / PIXELS, blue_on / PIXELS);
        }
    }
    free(off);
    free(on);
}

/* ---- Passes a view leaves out ------------------------------------------------------ */

/* sb_view.disabled_passes: a frame without the Purkinje shift, local tone
 * mapping, scene-linear grading, bloom and contact shadows, by the view's choice, is the
 * frame of a renderer made without them, bit for bit; with them it is not
 * (dusk, so that every one changes it). */
static void test_disabled_passes(void)
{
    struct sb_renderer_params with = base_params, without = base_params;
    with.purkinje = true;
    with.local_contrast = 0.7;
    with.grading = (struct sb_grading){.enabled = true, .white_balance_k = 5000.0, .saturation = 1.2, .contrast = 1.1};
    without.bloom_strength = -1.0;
    without.no_contact_shadows = true;
    struct frame *left_out = malloc(sizeof(*left_out)), *made_without = malloc(sizeof(*made_without));
    struct frame *all = malloc(sizeof(*all));
    struct sb_view v = view_at(-5.0);
    struct sb_view off = v;
    off.disabled_passes = 1u << SB_PASS_PURKINJE | 1u << SB_PASS_LOCAL_TONEMAP | 1u << SB_PASS_GRADE_LINEAR |
                          1u << SB_PASS_BLOOM | 1u << SB_PASS_CONTACT_SHADOWS |
                          1u << SB_PASS_SCENE; /* the scene is not optional: drawn anyway */
    if (render(&with, &off, left_out, "the passes left out") && render(&without, &v, made_without, "made without") &&
        render(&with, &v, all, "with them")) {
        CHECK(!memcmp(left_out->ldr, made_without->ldr, sizeof(left_out->ldr)) &&
                  !memcmp(left_out->hdr, made_without->hdr, sizeof(left_out->hdr)),
              "passes left out by the view: not the frame of a renderer without them");
        CHECK(memcmp(all->ldr, made_without->ldr, sizeof(all->ldr)) != 0, "the passes change nothing at dusk");
    }
    free(left_out);
    free(made_without);
    free(all);
}

/* The viewer's keys 1 to 8, from the passes' table, are the switches
 * docs/skyview.md lists, in its order. */
static void test_toggles(void)
{
    static const uint32_t documented[] = {
        1u << SB_PASS_FOG | 1u << SB_PASS_FOG_APPLY,
        1u << SB_PASS_CONTACT_SHADOWS,
        1u << SB_PASS_CLOUDS,
        1u << SB_PASS_PURKINJE,
        1u << SB_PASS_LOCAL_TONEMAP,
        1u << SB_PASS_GRADE_LINEAR,
        1u << SB_PASS_BLOOM,
        1u << SB_PASS_GRADE,
    };
    uint32_t toggles[SB_PASS_COUNT];
    int n = sb_pass_toggles(toggles);
    CHECK(n == (int)(sizeof(documented) / sizeof(documented[0])), "%d toggles", n);
    for (int i = 0; i < n && i < (int)(sizeof(documented) / sizeof(documented[0])); i++)
        CHECK(toggles[i] == documented[i], "key %d switches %#x, documented %#x", i + 1, toggles[i], documented[i]);
}

int main(int argc, char **argv)
{
    test_toggles();
    /* The world file; argv[1] overrides the source tree's (for runs elsewhere). */
    const char *world_path = argc > 1 ? argv[1] : TEST_WORLD;
    test_colour_science();
    enum sb_result res = test_vulkan(true, &vk);
    if (res == SB_ERR_NO_DEVICE)
        return test_no_device();
    if (res)
        return test_finish("post");

    char dir[256];
    CHECK(test_temp_dir("skyview-post", dir, sizeof(dir)), "temporary directory");
    test_view_pack(vk, dir, "post test", &pack);
    CHECK(sb_world_load(world_path, NULL, &world) == SB_OK, "the world loads");
    if (pack.scene && world.vertices) {
        test_linear_grading();
        test_display_lut();
        test_log_lut();
        test_local_tonemap();
        test_purkinje();
        test_disabled_passes();
    }
    CHECK(sb_vk_validation_messages(vk) == 0, "%u validation messages", sb_vk_validation_messages(vk));
    sb_vk_destroy(&vk);
    sb_world_finish(&world);
    sb_pack_close(&pack);
    CHECK(test_remove_dir(dir), "clean up");
    return test_finish("post");
}
