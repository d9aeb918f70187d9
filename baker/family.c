#include "family.h"

#include <assert.h>

static const struct sb_family_baker *const families[SB_FAMILY_COUNT] = {
#define SB_FAMILY(id, name) [SB_FAMILY_##id] = &sb_##name##_family,
#include "products.def"
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
