#include "family.h"

#include <assert.h>

static const struct sb_family_baker *const families[SB_FAMILY_COUNT] = {
    [SB_FAMILY_ATMOSPHERE] = &sb_atmosphere_family,
    [SB_FAMILY_CLOUDS] = &sb_clouds_family,
    [SB_FAMILY_PROBES] = &sb_probes_family,
    [SB_FAMILY_REFLECTIONS] = &sb_reflection_family,
};

const struct sb_family_baker *sb_family_baker(enum sb_family family)
{
    assert((unsigned)family < SB_FAMILY_COUNT && families[family]);
    return families[family];
}

const struct sb_family_baker *sb_product_baker(enum sb_product_id id)
{
    return sb_family_baker(sb_product_format(id)->family);
}
