#include "key.h"

#include <stdarg.h>
#include <stdio.h>

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
