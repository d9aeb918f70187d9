/*
 * What skybake tells about packs, for people and for pipelines: info (what
 * a pack holds), verify (whether all of it holds) and diff (how two packs
 * differ, per artifact). Packs are read with sb_pack_open, so everything
 * compared or printed has been verified (format version, files, shapes,
 * finite values, content hashes, scene).
 */
#ifndef SB_BAKER_PACK_TOOLS_H
#define SB_BAKER_PACK_TOOLS_H

#include <stdbool.h>
#include <stdint.h>

#include "pack.h"

/*
 * A contact sheet of the pack's reflection cubes as an 8-bit sRGB PNG: a
 * block a cube (the sky-only probe's first), a row a mip (sharp to rough),
 * each row the six faces as the file stores them (+x, -x, +y, -y, +z, -z),
 * every face drawn 48 x 48 (nearest texel) with 2-pixel gaps; one exposure
 * for the sheet (the first cube's level 0 mean luminance to 0.18),
 * x / (1 + x) per channel. SB_ERR_USAGE when the pack has no cubes.
 */
enum sb_result sb_pack_contact_sheet(const struct sb_pack *pack, const char *png_path);

/* The probe layout as a PNG, a top view (north, -z, up) of the
 * sky_visibility probes' footprint, 1024 pixels along its longer side:
 * the grid's probes white, the detail's amber over their brick columns
 * (dark blue), explicit probes green, each dot as bright as the sky the
 * probe sees, invalid probes red. SB_ERR_USAGE without sky_visibility. */
enum sb_result sb_pack_probe_map(const struct sb_pack *pack, const char *png_path);

/* Print the open pack read from `dir` as a table, or as one JSON object, on stdout. */
void sb_pack_info_print(const struct sb_pack *pack, const char *dir, bool json);

/* Verify the pack in `dir`, every problem logged as found; then print a
 * summary line (or, with `json`, one object listing every problem) on
 * stdout. Returns the first problem's code, SB_OK when all holds. */
enum sb_result sb_pack_verify_print(const char *dir, bool json);

/* How one artifact of pack A compares with B's, from best to worst. */
enum sb_diff_outcome {
    SB_DIFF_IDENTICAL, /* the same values, bit for bit */
    SB_DIFF_WITHIN,    /* every value within the relative tolerance */
    SB_DIFF_DIFFERENT, /* some value beyond it, or another shape */
    SB_DIFF_MISSING,   /* in one pack only */
};

struct sb_value_place {
    uint32_t x, y, z, channel;
};

struct sb_artifact_diff {
    enum sb_product_id product;
    enum sb_diff_outcome outcome;
    bool in_a, in_b;
    uint64_t values, differing; /* values compared; how many are not equal */
    uint64_t beyond;            /* how many differ by more than the tolerance */
    double max_abs, max_rel;
    struct sb_value_place max_abs_at, max_rel_at;
};

/*
 * Relative difference of values a and b of a channel whose largest
 * magnitude (in either pack) is `peak`: |a - b| / max(|a|, |b|, floor * peak),
 * so values far below the channel's scale are compared against that scale
 * (the floor the accuracy reports use, 1e-3 by default).
 */
double sb_diff_relative(double a, double b, double peak, double floor);

/* Compare every product of A and B; returns the worst outcome. */
enum sb_diff_outcome sb_pack_diff(const struct sb_pack *a, const struct sb_pack *b, double tolerance, double floor,
                                  struct sb_artifact_diff out[SB_PRODUCT_COUNT]);

/* Print the comparison as a table, or as one JSON object, on stdout. */
void sb_pack_diff_print(const struct sb_pack *a, const char *dir_a, const struct sb_pack *b, const char *dir_b,
                        double tolerance, double floor, const struct sb_artifact_diff diffs[SB_PRODUCT_COUNT],
                        bool json);

const char *sb_diff_outcome_name(enum sb_diff_outcome outcome);

#endif
