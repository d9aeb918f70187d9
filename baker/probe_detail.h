/*
 * Detail probes where geometry is (docs/probes.md, "Detail"): brick
 * columns of a lattice (formats/probes.h) over every place where a ray
 * straight down passes a covered gap, open space at least the scene's
 * detail spacing high between two surfaces (a room under its roof, the
 * ground under a bridge or an overhang; not the inside of a solid, nor the
 * hand's breadth under a car), from the lowest surface to one step over
 * the highest, and a lattice column around each such place; the scene's
 * detail volumes then force or forbid it. Open ground, which the grid's
 * layers follow, gets none.
 */
#ifndef SB_BAKER_PROBE_DETAIL_H
#define SB_BAKER_PROBE_DETAIL_H

#include <stdint.h>

#include "probes.h"
#include "raycast.h"
#include "result.h"
#include "scene.h"

struct sb_level;
struct sb_bvh;

/*
 * The brick columns `spacing` apart over the level into layout's detail
 * fields (detail_spacing_m, detail_origin_m, columns, column_count,
 * detail_count; its other fields untouched). Rays are cast through rc,
 * over bvh (whose root bounds the world). SB_ERR_TOO_LARGE, logged, when
 * the lattice would pass SB_PROBES_MAX_LATTICE steps or the columns
 * SB_PROBES_MAX_COLUMNS; past the columns' or the probes' cap under a
 * `budget` (whose caller coarsens) it is logged as a note, not an error.
 * None found: column_count 0.
 */
enum sb_result sb_probe_detail_place(struct sb_raycaster *rc, const struct sb_bvh *bvh, const struct sb_level *level,
                                     const struct sb_probe_params *params, double spacing, bool budget,
                                     struct sb_probe_layout *layout);

/* Check, from the scene and its world alone, that the lattice fits its
 * caps at `spacing` (the message names probes.detail_spacing_m). */
enum sb_result sb_probe_detail_check(const struct sb_level *level, const struct sb_probe_params *params,
                                     double spacing);

/* The detail probes' positions (layout's columns, in their order) into
 * positions[3 i ..]. */
void sb_probe_detail_positions(const struct sb_probe_layout *layout, float *positions);

#endif
