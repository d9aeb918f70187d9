#include "family.h"

#include <assert.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static const struct sb_family_baker *const families[SB_FAMILY_COUNT] = {
#define SB_FAMILY(id, name) [SB_FAMILY_##id] = &sb_##name##_family,
#include "products.def"
};

const struct sb_family_baker *sb_family_baker(enum sb_family family)
{
    assert((unsigned)family < SB_FAMILY_COUNT && families[family]);
    return families[family];
}

void sb_settings_json_add(char *json, size_t size, const char *fmt, ...)
{
    size_t len = strlen(json);
    if (!len || json[len - 1] != '}')
        return;
    char fields[1024];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(fields, sizeof(fields), fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof(fields) || len + (size_t)n >= size)
        return;
    snprintf(json + len - 1, size - (len - 1), "%s}", fields);
}

const struct sb_family_baker *sb_product_baker(enum sb_product_id id)
{
    return sb_family_baker(sb_product_format(id)->family);
}
