/*
 * The DFG (split-sum) LUT of GGX specular image-based lighting (Karis 2013;
 * Filament's multiple-scattering form), the first product of the
 * reflection family (issue 18): RG at SB_DFG_SIZE^2 (config.h), x the
 * Fresnel-weighted part and y the whole of the directional albedo of GGX
 * with height-correlated Smith visibility, so that a runtime's specular
 * ambient is prefiltered radiance times (x + f0 (y - x)) and its energy
 * compensation 1 + f0 (1 / y - 1). Baked on the device; dfg_ref.c is the
 * fp64 reference.
 */
#ifndef SB_BAKER_DFG_H
#define SB_BAKER_DFG_H

#include "compute.h"
#include "config.h"
#include "context.h"
#include "image.h"

/* Bake the LUT into *image (SB_DFG_SIZE^2, channels "dfg.x,dfg.y"). */
enum sb_result sb_dfg_bake(struct sb_vk *vk, struct sb_image *image, double *gpu_ms);
/* The kernel sb_dfg_bake makes. */
struct sb_pipeline_params sb_dfg_kernel(void);

/* XXH3-128 of the kernel's SPIR-V, for bake keys. */
void sb_dfg_code_hash(char out[33]);

/*
 * The reference, fp64 (dfg_ref.c): the same integrals at n.v and
 * perceptual roughness r, by composite Gauss-Legendre in GGX's (cos theta_h,
 * phi) inverse CDF, `panels` panels of 8 nodes in each (a few hundred: the
 * visible-hemisphere edge is a kink); out[0] = x, out[1] = y.
 */
void sb_dfg_reference(double n_v, double r, int panels, double out[2]);

/* The same by direct integration over the light's hemisphere (theta_l,
 * phi_l), for rough surfaces (r >= 0.5) where D is smooth: a second,
 * independent route. */
void sb_dfg_reference_direct(double n_v, double r, int panels, double out[2]);

#endif
