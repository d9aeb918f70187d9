/*
 * The detail probes' sight masks (docs/probes.md, "Leaks"): for each detail
 * probe, which points of the 8 lattice cells around it it sees in a
 * straight line, as SB_PROBE_SIGHT_SAMPLES bits (shaders/config.h). A
 * runtime reading a point between lattice probes weighs each by the
 * interpolated bits around the point, so a probe on the far side of a wall
 * lights nothing on this side. Exact ray casts, no statistics; the same
 * bits on every run.
 */
#ifndef SB_BAKER_PROBE_SIGHT_H
#define SB_BAKER_PROBE_SIGHT_H

#include <stdint.h>

#include "raycast.h"

/* The kernel sb_probe_sight_bake makes, for a BVH of instances or not. */
struct sb_pipeline_params sb_probe_sight_kernel(bool instanced);

/*
 * The masks of probe_count probes at positions (xyz in m each, where
 * they stand) whose lattice points are lattice (xyz in m each), spacing_m
 * apart, against the raycaster's BVH into out[SB_PROBE_SIGHT_WORDS *
 * probe_count]. *gpu_ms (may be NULL) gets the GPU time.
 */
enum sb_result sb_probe_sight_bake(struct sb_raycaster *raycaster, const float *positions, const float *lattice,
                                   uint32_t probe_count, float spacing_m, uint32_t *out, double *gpu_ms);

/* XXH3-128 of the kernel's SPIR-V, for bake keys. */
void sb_probe_sight_code_hash(char out[33]);

/* Sample point b (a bit index) of a probe whose lattice point is lattice,
 * spacing_m apart (config.h's rule), in fp64. */
void sb_probe_sight_point(const double lattice[3], double spacing_m, uint32_t b, double out[3]);

#endif
