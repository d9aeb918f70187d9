#include "family.h"

#include <assert.h>

static const struct sb_family_format families[SB_FAMILY_COUNT] = {
    [SB_FAMILY_ATMOSPHERE] =
        {
            .name = "atmosphere",
            .default_products = true,
        },
    [SB_FAMILY_CLOUDS] =
        {
            .name = "clouds",
            .section = "clouds",
            .parse_section = sb_clouds_section_parse,
            .section_json = sb_clouds_section_json,
            .product_size = sb_clouds_product_size,
            .no_tolerance = "the cloud noise is baked exactly (bit for bit with its CPU reference) and takes no "
                            "tolerance",
        },
    [SB_FAMILY_PROBES] =
        {
            .name = "probes",
            .section = "probes",
            .parse_section = sb_probes_section_parse,
            .section_json = sb_probes_section_json,
            .no_tolerance = "the probes' error is set by their ray count (probes.rays), not by a tolerance",
        },
    [SB_FAMILY_REFLECTIONS] =
        {
            .name = "reflections",
            .no_tolerance = "the DFG LUT is baked at one fixed setting (within 1e-3 of its fp64 reference)",
        },
};

const struct sb_family_format *sb_family_format(enum sb_family family)
{
    assert((unsigned)family < SB_FAMILY_COUNT);
    return &families[family];
}
