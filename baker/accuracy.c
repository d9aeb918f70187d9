#include "accuracy.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere_ref.h"
#include "parallel.h"

#define LOOKUP_X 509
#define LOOKUP_Y 127
#define MAX_SAMPLED_TEXELS 128
#define FLOOR_FRACTION 1e-3

struct sb_accuracy_ref {
    enum sb_product_id id;
    bool lookup;
    const struct sb_atmosphere_params *params;
    const struct sb_image *inputs;
    uint32_t width, height, channels;
    /* Probe i is texel (xs[i], ys[i]) of the bake, or for a lookup the
     * point (us[i], vs[i]) in unit coordinates. */
    uint32_t count;
    uint32_t *xs, *ys;
    double *us, *vs;
    double *values;  /* count x channels */
    double floor[9]; /* per channel: values below it compare against it */
    char probe[96];
};

static const int ms_x[] = {0, 5, 10, 13, 14, 15, 16, 17, 20, 25, 31}, ms_y[] = {0, 1, 4, 10, 20, 28, 31};
static const int irr_x[] = {0, 16, 26, 27, 28, 29, 30, 31, 32, 33, 36, 45, 63}, irr_y[] = {0, 3, 9, 15};
/* Sparse: the sun high, at the horizon and just below it; ground, middle, top. */
static const int ms_sparse_x[] = {5, 14, 16, 17, 25}, ms_sparse_y[] = {0, 10, 31};
static const int irr_sparse_x[] = {16, 29, 31, 33, 45}, irr_sparse_y[] = {0, 9, 15};

static double texel_unit(uint32_t i, uint32_t n)
{
    return (double)i / (n - 1);
}

static void evaluate(void *user, int i)
{
    struct sb_accuracy_ref *ref = user;
    const struct sb_atmosphere_params *p = ref->params;
    double *out = ref->values + (size_t)i * ref->channels;
    double r, mu;
    if (ref->id == SB_PRODUCT_TRANSMITTANCE) {
        double u = ref->lookup ? ref->us[i] : texel_unit(ref->xs[i], ref->width);
        double v = ref->lookup ? ref->vs[i] : texel_unit(ref->ys[i], ref->height);
        sb_ref_transmittance_geometry(p, u, v, &r, &mu);
        sb_ref_transmittance(p, r, mu, 8, out);
        return;
    }
    double mu_s = 2.0 * texel_unit(ref->xs[i], ref->width) - 1.0;
    double h = (p->top_radius_km - p->ground_radius_km) * texel_unit(ref->ys[i], ref->height);
    const struct sb_image *in = ref->inputs;
    if (ref->id == SB_PRODUCT_MULTISCATTERING)
        sb_ref_multiscattering(p, h, mu_s, NULL, out);
    else if (ref->id == SB_PRODUCT_IRRADIANCE_GROUND)
        sb_ref_irradiance_ground(p, h, mu_s, &in[SB_PRODUCT_MULTISCATTERING], NULL, out, out + 3);
    else
        sb_ref_irradiance_sky(p, h, mu_s, &in[SB_PRODUCT_MULTISCATTERING], &in[SB_PRODUCT_IRRADIANCE_GROUND], NULL,
                              out);
}

enum sb_result sb_accuracy_ref_create(const struct sb_atmosphere_params *params, enum sb_product_id id, unsigned flags,
                                      uint32_t width, uint32_t height, const struct sb_image inputs[SB_PRODUCT_COUNT],
                                      struct sb_accuracy_ref **out)
{
    const struct sb_product_format *format = sb_product_format(id);
    struct sb_accuracy_ref *ref = calloc(1, sizeof(*ref));
    *out = NULL;
    if (!ref)
        return SB_ERR_NOMEM;
    ref->id = id;
    ref->lookup = (flags & SB_ACCURACY_LOOKUP) && id == SB_PRODUCT_TRANSMITTANCE;
    ref->params = params;
    ref->inputs = inputs;
    ref->width = width && id == SB_PRODUCT_TRANSMITTANCE ? width : format->width;
    ref->height = height && id == SB_PRODUCT_TRANSMITTANCE ? height : format->height;
    ref->channels = format->channel_count;

    const int *xs = NULL, *ys = NULL;
    uint32_t nx, ny;
    if (id == SB_PRODUCT_TRANSMITTANCE) {
        nx = ref->lookup ? LOOKUP_X : ref->width;
        ny = ref->lookup ? LOOKUP_Y : ref->height;
        snprintf(ref->probe, sizeof(ref->probe),
                 ref->lookup ? "%u x %u points between texels, T > 1e-6" : "every texel (%u x %u) with T > 1e-6", nx,
                 ny);
    } else {
        bool ms = id == SB_PRODUCT_MULTISCATTERING;
        if (flags & SB_ACCURACY_SPARSE) {
            xs = ms ? ms_sparse_x : irr_sparse_x;
            ys = ms ? ms_sparse_y : irr_sparse_y;
            nx = 5;
            ny = 3;
        } else {
            xs = ms ? ms_x : irr_x;
            ys = ms ? ms_y : irr_y;
            nx = ms ? 11 : 13;
            ny = ms ? 7 : 4;
        }
        snprintf(ref->probe, sizeof(ref->probe), "%u x %u texels, crowded at twilight", nx, ny);
    }
    ref->count = nx * ny;
    ref->xs = calloc(ref->count, sizeof(*ref->xs));
    ref->ys = calloc(ref->count, sizeof(*ref->ys));
    ref->us = calloc(ref->count, sizeof(*ref->us));
    ref->vs = calloc(ref->count, sizeof(*ref->vs));
    ref->values = calloc((size_t)ref->count * ref->channels, sizeof(*ref->values));
    if (!ref->xs || !ref->ys || !ref->us || !ref->vs || !ref->values) {
        sb_accuracy_ref_destroy(&ref);
        return SB_ERR_NOMEM;
    }
    for (uint32_t k = 0; k < ref->count; k++) {
        uint32_t i = k % nx, j = k / nx;
        ref->xs[k] = xs ? (uint32_t)xs[i] : i;
        ref->ys[k] = ys ? (uint32_t)ys[j] : j;
        ref->us[k] = (i + 0.5) / nx;
        ref->vs[k] = (j + 0.5) / ny;
    }
    sb_parallel_for((int)ref->count, evaluate, ref);

    for (uint32_t c = 0; c < ref->channels; c++) {
        double peak = 0;
        for (uint32_t k = 0; k < ref->count; k++)
            peak = fmax(peak, fabs(ref->values[(size_t)k * ref->channels + c]));
        ref->floor[c] = id == SB_PRODUCT_TRANSMITTANCE ? 0.0 : FLOOR_FRACTION * peak;
    }
    *out = ref;
    return SB_OK;
}

void sb_accuracy_ref_destroy(struct sb_accuracy_ref **pref)
{
    struct sb_accuracy_ref *ref = *pref;
    if (!ref)
        return;
    free(ref->xs);
    free(ref->ys);
    free(ref->us);
    free(ref->vs);
    free(ref->values);
    free(ref);
    *pref = NULL;
}

const char *sb_accuracy_ref_probe(const struct sb_accuracy_ref *ref)
{
    return ref->probe;
}

/* v rounded to the nearest half-precision value (ties to even), as an EXR
 * HALF channel would store it; beyond the largest half it is infinite. */
static double round_to_half(double v)
{
    if (v == 0.0 || !isfinite(v))
        return v;
    double a = fabs(v), q;
    if (a < 0x1p-14) {
        q = rint(a * 0x1p24) * 0x1p-24; /* subnormal: a fixed quantum */
    } else {
        int e;
        double m = frexp(a, &e); /* a = m 2^e, m in [0.5, 1) */
        q = ldexp(rint(ldexp(m, 11)), e - 11);
    }
    if (q > 65504.0)
        q = INFINITY;
    return copysign(q, v);
}

void sb_accuracy_measure(const struct sb_accuracy_ref *ref, const struct sb_image *image, bool as_half,
                         struct sb_error *err)
{
    memset(err, 0, sizeof(*err));
    if (image->channel_count != ref->channels ||
        (!ref->lookup && (image->width != ref->width || image->height != ref->height))) {
        err->max_rel = err->rms_rel = INFINITY;
        return;
    }
    struct sb_image half = {0};
    const struct sb_image *read = image;
    if (as_half) {
        if (sb_image_init(&half, image->width, image->height, image->channel_count)) {
            err->max_rel = err->rms_rel = INFINITY;
            return;
        }
        size_t n = sb_image_float_count(image);
        for (size_t i = 0; i < n; i++)
            half.data[i] = (float)round_to_half(image->data[i]);
        read = &half;
    }
    double acc = 0;
    for (uint32_t k = 0; k < ref->count; k++) {
        double got[9];
        if (ref->lookup) {
            double r, mu;
            sb_ref_transmittance_geometry(ref->params, ref->us[k], ref->vs[k], &r, &mu);
            sb_ref_transmittance_lookup(ref->params, read, r, mu, got);
        } else {
            size_t at = ((size_t)ref->ys[k] * read->width + ref->xs[k]) * ref->channels;
            for (uint32_t c = 0; c < ref->channels; c++)
                got[c] = read->data[at + c];
        }
        for (uint32_t c = 0; c < ref->channels; c++) {
            double want = ref->values[(size_t)k * ref->channels + c];
            if (ref->id == SB_PRODUCT_TRANSMITTANCE && want <= 1e-6)
                continue;
            double scale = fmax(fabs(want), ref->floor[c]);
            double rel = scale > 0 ? fabs(got[c] - want) / scale : fabs(got[c]);
            if (!isfinite(rel)) /* NaN must fail, not compare false */
                rel = INFINITY;
            acc += rel * rel;
            err->count++;
            if (err->count == 1 || rel > err->max_rel) {
                err->max_rel = rel;
                err->worst_x = ref->lookup ? (uint32_t)(ref->us[k] * read->width) : ref->xs[k];
                err->worst_y = ref->lookup ? (uint32_t)(ref->vs[k] * read->height) : ref->ys[k];
                err->worst_channel = c;
            }
        }
    }
    err->rms_rel = err->count ? sqrt(acc / err->count) : 0.0;
    sb_image_finish(&half);
}
