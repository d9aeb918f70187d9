/*
 * The light at points among a world's surfaces, path traced in fp64 on
 * Embree's rays: the reference the probes' visibility and bounce
 * (sky_visibility.h, sky_bounce.h) are measured against. The world is
 * Lambertian (each triangle its material's albedo; both faces alike, as
 * the bake takes them); it is lit by a sky of radiance given as order-2 SH
 * (the form a runtime relights the probes with) and a sun, a direction of
 * given irradiance, sampled at every surface a path meets (next event
 * estimation with a shadow ray). A point's irradiance is split into the
 * sky it sees directly and the light of the surfaces it sees (every
 * bounce, or the first n); the sun it sees directly, which shadow maps and
 * traced shadows own, is in neither.
 */
#ifndef SB_BAKER_SKY_BOUNCE_REF_H
#define SB_BAKER_SKY_BOUNCE_REF_H

#include <stdbool.h>
#include <stdint.h>

#include "config.h"
#include "embree_ref.h"
#include "mesh.h"

struct sb_bounce_lighting {
    double sky[SB_PROBE_SH][3]; /* the sky's radiance, order-2 SH per channel (never negative where it is read) */
    double sun_dir[3];          /* unit, toward the sun */
    double sun[3];              /* the sun's irradiance, normal to it */
};

/* The axes a point's irradiance is taken about: +x, -x, +y, -y, +z, -z. */
#define SB_BOUNCE_REF_NORMALS 6

struct sb_bounce_irradiance {
    double sky[SB_BOUNCE_REF_NORMALS][3];     /* irradiance of the sky seen directly */
    double bounced[SB_BOUNCE_REF_NORMALS][3]; /* of the surfaces seen (their sun and sky, bounced) */
    /* the standard error of each, from the paths' spread */
    double sky_error[SB_BOUNCE_REF_NORMALS][3];
    double bounced_error[SB_BOUNCE_REF_NORMALS][3];
    /* the mean over the axes of the channels' sum, of the sky, of the
     * surfaces and of both, and the standard error of each */
    double mean[3], mean_error[3];
};

/*
 * Trace `paths` paths from each of `count` points (xyz m) in fp64 on e (a
 * scene of `mesh`), their first directions uniform over the sphere, each
 * path ended by Russian roulette past its second surface, or at surface
 * `bounces` (0: none). Deterministic for a seed, whatever the cores.
 * False when a material is textured (not modelled here) or memory runs out.
 */
bool sb_bounce_path_trace(const struct sb_mesh *mesh, const struct sb_embree *e, const double *points,
                          uint32_t count, const struct sb_bounce_lighting *light, uint32_t paths, uint32_t bounces,
                          uint64_t seed, struct sb_bounce_irradiance *out);

/* The axis normal i (SB_BOUNCE_REF_NORMALS). */
void sb_bounce_ref_normal(int i, double n[3]);

#endif
