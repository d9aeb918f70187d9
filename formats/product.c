#include "product.h"

#include <string.h>

#include "config.h"
#include "family.h"
#include "probes.h"

static const struct sb_product_format product_formats[SB_PRODUCT_COUNT] = {
#define SB_PRODUCT(id, family_id, since, ...)                                                                          \
    [SB_PRODUCT_##id] = {.since_version = since, .family = SB_FAMILY_##family_id, __VA_ARGS__},
#include "products.def"
};

/* The versions count up from 1, and each product came in one of them. */
#define SB_FORMAT_VERSION(version, what) _Static_assert(SB_FORMAT_VERSION_##version == version, what);
#define SB_PRODUCT(id, family, since, ...)                                                                             \
    _Static_assert(since >= 1 && since <= SB_PACK_FORMAT_VERSION, #id ": its format version is not in products.def");
#include "products.def"

const struct sb_product_format *sb_product_format(enum sb_product_id id)
{
    return &product_formats[id];
}

const char *sb_product_name(enum sb_product_id id)
{
    return (unsigned)id < SB_PRODUCT_COUNT ? product_formats[id].name : "unknown";
}

const char *sb_product_pixel_type(enum sb_product_id id, int format_version)
{
    const struct sb_product_format *f = &product_formats[id];
    return f->half_since && format_version < f->half_since ? "float32" : f->pixel_type;
}

bool sb_product_from_name(const char *name, enum sb_product_id *id)
{
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        if (strcmp(name, product_formats[p].name) == 0) {
            *id = (enum sb_product_id)p;
            return true;
        }
    return false;
}
