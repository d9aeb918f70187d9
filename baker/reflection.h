/*
 * Reflection probes (issue 18, docs/reflections.md): a cube of what a
 * probe sees, captured on the device by ray casts through the world's BVH
 * (reflection_capture.comp), prefiltered for GGX roughness into its mip
 * chain (reflection_prefilter.comp), and its irradiance as order-2 SH.
 * reflection_ref.c is the prefilter's fp64 reference.
 */
#ifndef SB_BAKER_REFLECTION_H
#define SB_BAKER_REFLECTION_H

#include <stdint.h>

#include "atmosphere.h"
#include "compute.h"
#include "mesh.h"
#include "raycast.h"
#include "surfaces.h"

/* The two kernels' pipelines, kept across the probes of a bake (creating
 * them takes seconds on some drivers); zero-initialise, destroy once. */
struct sb_reflection_kernels {
    struct sb_pipeline capture, prefilter;
};
void sb_reflection_kernels_destroy(struct sb_vk *vk, struct sb_reflection_kernels *kernels);

/* What a capture reads: the atmosphere's LUTs (a baker that has them) and
 * the world (rc NULL: the sky alone). */
struct sb_capture_inputs {
    struct sb_atmosphere_baker *atmosphere;
    struct sb_raycaster *rc;
    const struct sb_surfaces *surfaces;    /* what the BVH's triangles are (with rc) */
    struct sb_reflection_kernels *kernels; /* may be NULL: made for the call */
};

struct sb_capture_params {
    float origin_m[3];
    double altitude_km; /* the probe's, above the ground */
    double sun[3];      /* unit, toward the sun, y up */
    uint32_t face_size;
    uint32_t ambient_rays; /* from each surface hit, about */
    double sky_sh[9][3];   /* the sky's radiance, order-2 SH: what surfaces are lit by */
};

/* The kernels sb_reflection_capture and sb_reflection_prefilter make. */
struct sb_pipeline_params sb_reflection_capture_kernel(void);
struct sb_pipeline_params sb_reflection_prefilter_kernel(void);

/* Level 0 of a probe's cube, one rgba texel each (rgb radiance; a = 1
 * where the ray met a back face), 6 n^2 texels into out; and, when
 * `surfaces` is not NULL, SB_RELIGHT_VEC4S vec4s a texel of what
 * relighting needs (config.h: albedo, distance, normal, the sky's
 * transfer). */
enum sb_result sb_reflection_capture(struct sb_vk *vk, const struct sb_capture_inputs *in,
                                     const struct sb_capture_params *params, float *out, float *surfaces,
                                     double *gpu_ms);

/* How a cube is prefiltered: skybake's way (zero but `samples`), or the
 * published ones the bench compares with. */
struct sb_prefilter_params {
    uint32_t samples;      /* GGX samples a texel at mip 1 */
    bool constant_samples; /* the same count at every mip (else doubling per mip, sb_reflection_level_samples) */
    float lod_bias;        /* added to the filtered lookup's lod (Colbert and Krivanek's, Filament's: 1) */
    bool unfiltered;       /* every sample reads level 0 (Karis 2013) */
    struct sb_reflection_kernels *kernels; /* may be NULL: made for the call */
};

/* The prefiltered chain of one cube from its level 0 (rgba texels, 6 n^2);
 * level 0 is the source itself, a mirror. out: every level, rgba texels,
 * level by level (sb_cube_level_offset); *gpu_ms the dispatches' time. */
enum sb_result sb_reflection_prefilter(struct sb_vk *vk, const float *level0, uint32_t face_size,
                                       const struct sb_prefilter_params *params, float *out, double *gpu_ms);

/* The order-2 SH of a cube's level 0 (rgba texels) by exact texel solid
 * angles; the irradiance's (cosine-convolved) when `irradiance`. */
void sb_reflection_sh(const float *level0, uint32_t face_size, int irradiance, double sh[9][3]);

/* XXH3-128 of both kernels' SPIR-V, for bake keys. */
void sb_reflection_code_hash(char out[33]);

/*
 * The reference (reflection_ref.c, fp64): the GGX-convolved radiance at
 * direction n (unit) and perceptual roughness r of the cube whose level 0
 * is `level0` (rgba texels, face_size n), read bilinearly within each face
 * as the device reads it, by dense integration over every texel of the
 * whole cube, split into `sub` x `sub` pieces with their exact solid
 * angles: the integral of L(l) D(h) (n.l)+ over that of D(h) (n.l)+,
 * h = normalize(n + l). r = 0 returns the source at n.
 */
void sb_reflection_reference(const float *level0, uint32_t face_size, const double n[3], double r, int sub,
                             double out[3]);

#endif
