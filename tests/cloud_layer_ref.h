/*
 * The volumetric cloud layer skyview draws (shaders/cloud_layer.glsl), in
 * fp64 on the CPU: the same density field read from the same half values
 * (trilinear, repeating, as a Vulkan sampler reads them), the same lighting
 * model, each integral taken finely instead of in the runtime's few steps.
 * For the tests: what the frame's clouds converge to at a pixel.
 */
#ifndef SB_TESTS_CLOUD_LAYER_REF_H
#define SB_TESTS_CLOUD_LAYER_REF_H

#include "image.h"
#include "scene.h"

#define SB_CLOUD_REF_TABLE 21

struct sb_cloud_ref {
    const struct sb_atmosphere_params *atmosphere;
    const struct sb_image *transmittance; /* the pack's LUT, read bilinearly as the runtime reads it */
    const struct sb_image *noise[4];      /* cloud_shape, cloud_detail, cloud_curl, weather */
    struct sb_cloud_layer_params layer;
    double camera_m[3]; /* world, y up; the ground's plane at y = 0 */
    double sun[3];      /* unit, toward the sun */
    /* The ground's sky and bounce irradiance (irradiance reference) over
     * sun cosines about the camera's, for the ambient. */
    double mu_s0, mu_s_step;
    double e_up[SB_CLOUD_REF_TABLE][3], e_down[SB_CLOUD_REF_TABLE][3];
    int view_steps, light_steps, shadow_steps;
};

/* Fill the irradiance table (slow: the irradiance reference, 21 times) and
 * the step counts (view 4000, light 512, shadow 4000). `multiscattering` is
 * the pack's, which the irradiance reference reads. */
void sb_cloud_ref_init(struct sb_cloud_ref *ref, const struct sb_image *multiscattering);

/* The density in [0, 1] at q = (world x, altitude, world z), metres. */
double sb_cloud_ref_density(const struct sb_cloud_ref *ref, const double q[3]);

/* In-scattering (rgb, the pack's radiance units) and transmittance of the
 * clouds along unit world direction d from the camera, the ray ending at
 * scene_m metres (1e30: the sky). */
void sb_cloud_ref_march(const struct sb_cloud_ref *ref, const double d[3], double scene_m, double inscatter[3],
                        double *transmittance);

/* The clouds' transmittance toward the sun from world point p (below the layer). */
double sb_cloud_ref_sun_transmittance(const struct sb_cloud_ref *ref, const double p[3]);

#endif
