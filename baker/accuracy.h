/*
 * How far a baked product is from the fp64 reference (atmosphere_ref.h):
 * the reference is evaluated once at a product's probe points, then any
 * number of bakes of it are measured. skybake bench sweeps settings with
 * it; a scene's tolerance picks settings with it.
 *
 * Probe points and error measures, per product:
 * - transmittance: every texel whose reference T > 1e-6, relative error
 *   (at the bake's own resolution);
 * - transmittance lookup: the LUT read bilinearly, as the runtime reads it,
 *   at 509 x 127 points that fall between texels of every power-of-two
 *   resolution, against the exact value; T > 1e-6;
 * - multiscattering: 11 x 7 texels, irradiance_ground and irradiance_sky
 *   13 x 4, crowded at twilight (the sun within 10 degrees of the horizon),
 *   relative error, with values below 1e-3 of the channel's largest
 *   compared against that floor instead (a relative error at night means
 *   nothing).
 * A product that reads others is measured against a reference that reads
 * the same baked inputs: the error is the product's own.
 */
#ifndef SB_BAKER_ACCURACY_H
#define SB_BAKER_ACCURACY_H

#include <stdbool.h>
#include <stdint.h>

#include "image.h"
#include "pack.h"
#include "result.h"
#include "scene.h"

struct sb_error {
    double max_rel;
    double rms_rel;
    uint32_t count; /* values compared */
    uint32_t worst_x, worst_y, worst_channel;
};

struct sb_accuracy_ref;

enum sb_accuracy_flags {
    SB_ACCURACY_LOOKUP = 1 << 0, /* transmittance: measure the bilinear lookup, not the texels */
    SB_ACCURACY_SPARSE = 1 << 1, /* scattering products: 5 x 3 texels of the probe set's, a fifth
                                    of the reference's time (the hard-case tests) */
};

/*
 * The reference of product `id` (flags: sb_accuracy_flags) for a bake at
 * width x height (transmittance only; 0: the format's). `inputs` holds the
 * baked products `id` reads (the others may be empty).
 */
enum sb_result sb_accuracy_ref_create(const struct sb_atmosphere_params *params, enum sb_product_id id, unsigned flags,
                                      uint32_t width, uint32_t height, const struct sb_image inputs[SB_PRODUCT_COUNT],
                                      struct sb_accuracy_ref **ref);
void sb_accuracy_ref_destroy(struct sb_accuracy_ref **ref);

/* A short description of the probe points, for reports and manifests. */
const char *sb_accuracy_ref_probe(const struct sb_accuracy_ref *ref);

/* Measure `image` (the product as baked; as stored in half precision when
 * `as_half`). A non-finite value or a shape that does not match the
 * reference's is an infinite error. */
void sb_accuracy_measure(const struct sb_accuracy_ref *ref, const struct sb_image *image, bool as_half,
                         struct sb_error *error);

#endif
