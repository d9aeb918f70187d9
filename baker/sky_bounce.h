/*
 * The one-bounce transfer at probes (issue 17's bounce term; docs/probes.md,
 * "Bounce"): for each probe, B[m][k] per colour, m < 4 the order-1 SH of
 * the direction w at the probe and k < 9 the order-2 SH of the light
 * reaching the surface its ray along w hits. A runtime relights it for any
 * sky L (SH) and sun (direction s, irradiance E): the radiance bounced
 * toward the probe is, in the order-1 SH of w,
 *   b_m = sum_k B[m][k] (L_k + E Y_k(s)).
 * Lambertian surfaces; the surfaces' own sky visibility is cast from each
 * hit. Every bounce: the light the probe's surfaces send it lights them
 * again as it arrives at the probe (the probe's own field stands for
 * theirs, as DDGI's recursion does with its probes), so B becomes
 * B1 + M B1 + M M B1 + ..., M the kernel's 4 x 4 operator on order-1
 * light (config.h): every bounce as (I - M)^-1 B1 where the series
 * surely converges (M's largest row sum under 1), else summed until a
 * bounce adds under SB_SKY_BOUNCE_CONVERGED of the light so far; or a
 * stated count of bounces.
 * Deterministic: fixed ray sets, a fixed sum order, the sums in fp64.
 */
#ifndef SB_BAKER_SKY_BOUNCE_H
#define SB_BAKER_SKY_BOUNCE_H

#include <stdint.h>

#include "mesh.h"
#include "raycast.h"
#include "scene.h"
#include "surfaces.h"

struct sb_sky_bounce_params {
    uint32_t ray_count; /* rays a probe, a multiple of SB_PROBE_THREADS [256; the sun's 1024] */
    uint32_t secondary; /* about this many rays from each hit (a 2x spherical set, half cast) [64] */
    float tmin_m;       /* rays start this far from the probe [1e-4] */
    uint32_t bounces;   /* 1: one bounce; 0: until converged [0] */
    float tmax_m;       /* a ray (from the probe or a surface) reaching this far sees the sky [1e30] */
    bool sun;           /* the sun's table (sun_bounce) instead of B: `secondary` unused [false] */
};

#define SB_SKY_BOUNCE_CONVERGED 1e-3 /* a bounce adding less ends the sum */
#define SB_SKY_BOUNCE_CHUNK_BYTES (256u << 20) /* the kernel's output a dispatch at most */
#define SB_SKY_BOUNCE_MAX SB_PROBES_MAX_BOUNCES /* bounces at most (scene.h) */

/* What the bounces past the first added, over the valid probes. */
struct sb_sky_bounce_report {
    uint32_t most_bounces; /* the most terms any probe's series took (0: every probe in closed form) */
    double mean_added;     /* their light over the first bounce's, mean (the mean channel's constant band) */
    double most_added;     /* and the most */
};

/* The kernel sb_sky_bounce_bake runs, for a BVH of instances or not, for
 * the sun's table or not. */
struct sb_pipeline_params sb_sky_bounce_kernel(bool instanced, bool sun);

/*
 * Bake probe_count probes at positions (xyz in m each; valid[i] 0 gives the
 * probe zeros) against the raycaster's BVH into out[SB_BOUNCE_FLOATS *
 * probe_count] (config.h: B, m, then k, then rgb), or with params->sun
 * into out[SB_BOUNCE_SUN_TABLE * probe_count] (their sun tables:
 * sb_sky_bounce_sun_table). `surfaces` are what the
 * BVH's triangles are (their albedos and textures: the same meshes'). A
 * hit's albedo is its texture's at the ray cone's footprint (surface.glsl).
 * *gpu_ms (may be NULL) gets the GPU time, *report (may be NULL) what the
 * bounces past the first added.
 */
enum sb_result sb_sky_bounce_bake(struct sb_raycaster *raycaster, const struct sb_surfaces *surfaces,
                                  const float *positions, const float *valid, uint32_t probe_count,
                                  const struct sb_sky_bounce_params *params, float *out, double *gpu_ms,
                                  struct sb_sky_bounce_report *report);

/* Sum the bounces of one probe in place: `kernel` holds the kernel's
 * SB_BOUNCE_KERNEL_FLOATS (B1, then M; `sun`: then the sun's table); its
 * first SB_BOUNCE_FLOATS (and the table) become B1 + M B1 + ... to
 * `bounces` terms, or every bounce (0: (I - M)^-1 B1,
 * or the series until converged where M's row sums reach 1). Returns the
 * terms summed, 0 for the closed form or nothing to bounce; *added (may
 * be NULL) the light past the first's over the first's (constant band,
 * channels summed; 0 where B1's is 0). */
uint32_t sb_sky_bounce_sum(float *kernel, bool sun, uint32_t bounces, double *added);

/* The sun table a probe's record keeps (config.h, SB_BOUNCE_SUN_TABLE),
 * from its summed kernel output (sb_sky_bounce_sum): each direction's grey
 * constant band T_j, then the shape S[m] rgb, the table's order-1 rgb
 * summed over the directions over the T_j summed (0 where that is not
 * above 0), each within SB_SKY_BOUNCE_LIMIT. A sun of irradiance E from s
 * sends the probe E sum_j w_j(s) T_j S[m] (w: sb_sun_table_weights). */
void sb_sky_bounce_sun_table(const float *kernel, float table[SB_BOUNCE_SUN_TABLE]);

/* XXH3-128 of the kernel's SPIR-V (the sun's with `sun`; and the texture
 * mips'), for bake keys. */
void sb_sky_bounce_code_hash(bool sun, char out[33]);

#endif
