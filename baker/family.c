#include "family.h"

#include <assert.h>
#include <stdarg.h>
#include <stdio.h>

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

void sb_key_add(struct sb_key_text *key, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (key->length < sizeof(key->text)) {
        int w = vsnprintf(key->text + key->length, sizeof(key->text) - key->length, fmt, ap);
        key->length += w > 0 ? (size_t)w : 0;
    }
    va_end(ap);
}

void sb_key_add3(struct sb_key_text *key, const char *name, const double v[3])
{
    sb_key_add(key, " %s=%a,%a,%a", name, v[0], v[1], v[2]);
}
