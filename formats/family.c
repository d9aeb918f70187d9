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
            .set_defaults = sb_clouds_set_defaults,
            .parse_section = sb_clouds_section_parse,
            .section_json = sb_clouds_section_json,
            .product_shape = sb_clouds_product_shape,
            .no_tolerance = "the cloud noise is baked exactly (bit for bit with its CPU reference) and takes no "
                            "tolerance",
        },
    [SB_FAMILY_PROBES] =
        {
            .name = "probes",
            .section = "probes",
            .set_defaults = sb_probes_set_defaults,
            .parse_section = sb_probes_section_parse,
            .section_json = sb_probes_section_json,
            .validate = sb_probes_validate,
            .no_tolerance = "the probes' error is set by their ray count (probes.rays), not by a tolerance",
        },
    [SB_FAMILY_REFLECTIONS] =
        {
            .name = "reflections",
            .section = "reflections",
            .set_defaults = sb_reflections_set_defaults,
            .parse_section = sb_reflections_section_parse,
            .section_json = sb_reflections_section_json,
            .product_shape = sb_reflections_product_shape,
            .no_tolerance = "the reflections' accuracy is set by their sample counts (reflections.samples; the DFG "
                            "LUT's is fixed, within 1e-3 of its fp64 reference)",
        },
};

const struct sb_family_format *sb_family_format(enum sb_family family)
{
    assert((unsigned)family < SB_FAMILY_COUNT);
    return &families[family];
}

void sb_product_shape(const struct sb_scene *scene, enum sb_product_id id, uint32_t shape[3])
{
    const struct sb_product_format *f = sb_product_format(id);
    const struct sb_family_format *family = &families[f->family];
    shape[0] = f->width;
    shape[1] = f->height;
    shape[2] = f->depth;
    if (family->product_shape)
        family->product_shape(scene, id, shape);
}
