/*
 * A bake key's text: what a product's value depends on, appended by its
 * family (family.h) and by bake.c, then hashed (bake.h says what goes in).
 */
#ifndef SB_BAKER_KEY_H
#define SB_BAKER_KEY_H

#include <stddef.h>

/* A bake key's text, before it is hashed (bake.h says what goes in). */
struct sb_key_text {
    char text[8192];
    size_t length; /* may exceed sizeof(text) - 1 when cut; hashing takes what fits */
};

/* Append printf-style text to a key's text. */
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
void sb_key_add(struct sb_key_text *key, const char *fmt, ...);

/* Append " name=%a,%a,%a" (hexadecimal floats: exact). */
void sb_key_add3(struct sb_key_text *key, const char *name, const double v[3]);

#endif
