/*
 * Sky visibility at probes (issue 17): at each probe, the order-2 SH
 * projection of the sky's visibility (1 where a ray escapes the geometry,
 * 0 where it hits), with the fraction of rays that met a back face (a
 * probe inside geometry sees mostly back faces: DDGI's test), the fraction
 * that hit anything and their mean distance. Rays: config.h's spherical
 * Fibonacci set, the same for every probe, so a bake is deterministic.
 * The pack product, its scene section and the bounce term build on this.
 */
#ifndef SB_BAKER_SKY_VISIBILITY_H
#define SB_BAKER_SKY_VISIBILITY_H

#include <stdint.h>

#include "raycast.h"

struct sb_sky_visibility_params {
    uint32_t ray_count; /* per probe, a multiple of SB_PROBE_THREADS up to SB_PROBE_MAX_RAYS [2048] */
    float tmin_m;       /* rays start this far from the probe [1e-4] */
    float tmax_m;       /* a ray reaching this far sees the sky [1e30: the geometry's own extent] */
    const char *what;   /* its progress's name ["sky visibility: probes' rays"] */
};

/* The kernel sb_sky_visibility_bake makes, for a BVH of instances or not. */
struct sb_pipeline_params sb_sky_visibility_kernel(bool instanced);

/*
 * Bake probe_count probes at positions (xyz in m each) against the
 * raycaster's BVH into out[SB_VISIBILITY_FLOATS * probe_count] (config.h): the
 * SH coefficients (4 pi / n times the sum over escaping rays of the basis),
 * then the back-face fraction, the hit fraction and the mean hit distance.
 * The coefficients are as projected (not deringed: sb_sh9_dering).
 * *gpu_ms (may be NULL) gets the GPU time.
 */
enum sb_result sb_sky_visibility_bake(struct sb_raycaster *raycaster, const float *positions, uint32_t probe_count,
                                      const struct sb_sky_visibility_params *params, float *out, double *gpu_ms);

/* The order a probe's n rays are cast in: the directions sorted along a
 * Morton curve of their octahedral coordinates (ties by index), so that
 * neighbouring invocations trace neighbouring directions. A permutation of
 * 0..n-1; the identity if memory runs out. */
void sb_probe_ray_order(uint32_t n, uint32_t *order);

/* The n rays of a probe at `position` in the raycast kernel's layout
 * (raycast.h: origin, tmin; direction, tmax 1e30), as the bake casts them
 * (before its ordering): for references that cast them elsewhere (Embree). */
void sb_probe_rays(const float position[3], uint32_t n, float tmin, float *rays);

/* XXH3-128 of the kernel's SPIR-V, for bake keys. */
void sb_sky_visibility_code_hash(char out[33]);

#endif
