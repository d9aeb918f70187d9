#include "family.h"

#include <assert.h>

static const struct sb_family_format *const families[SB_FAMILY_COUNT] = {
#define SB_FAMILY(id, name) [SB_FAMILY_##id] = &sb_##name##_family_format,
#include "products.def"
};

const struct sb_family_format *sb_family_format(enum sb_family family)
{
    assert((unsigned)family < SB_FAMILY_COUNT);
    return families[family];
}

void sb_product_shape(const struct sb_scene *scene, enum sb_product_id id, uint32_t shape[3])
{
    const struct sb_product_format *f = sb_product_format(id);
    const struct sb_family_format *family = families[f->family];
    shape[0] = f->width;
    shape[1] = f->height;
    shape[2] = f->depth;
    if (family->product_shape)
        family->product_shape(scene, id, shape);
}
