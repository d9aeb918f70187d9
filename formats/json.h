/*
 * Strict JSON reading shared by the scene and manifest parsers: one value,
 * nothing after it but whitespace, UTF-8 only, no NUL bytes (nor escaped
 * ones), no key given twice, and a
 * size cap checked before parsing. Errors name the source and the line.
 */
#ifndef SB_JSON_H
#define SB_JSON_H

#include <cJSON.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "result.h"

/* The offset of the first byte of text[size] that does not begin a valid
 * UTF-8 sequence (overlong forms, surrogates and values past U+10FFFF are
 * invalid), or SIZE_MAX when all of it is UTF-8. */
size_t sb_utf8_check(const char *text, size_t size);

/* Parse `size` bytes of `text`, which must be UTF-8 with no string escaping
 * a NUL (\u0000); on success the caller owns *root (cJSON_Delete). */
enum sb_result sb_json_parse(const char *text, size_t size, const char *source, cJSON **root);

/*
 * Read and parse the file `path` (relative to the directory fd `dir`, or
 * AT_FDCWD) of at most max_bytes. With follow_symlinks false a symbolic
 * link is refused (SB_ERR_UNSAFE_PATH). `source` names the file in messages.
 */
enum sb_result sb_json_load(int dir, const char *path, const char *source, size_t max_bytes, bool follow_symlinks,
                            cJSON **root);

/* SB_ERR_DUPLICATE_KEY, logged as source: where.key, if `object` has a key twice. */
enum sb_result sb_json_check_duplicates(const cJSON *object, const char *source, const char *where);

/* Print `root` formatted, and a newline, to `out`, then cJSON_Delete it
 * (accepts NULL). False when memory or the write failed. */
bool sb_json_emit(FILE *out, cJSON *root);

/* `obj` must be an object of no keys but `keys` (NULL-terminated), none
 * twice; logs "source: section.key: reason" otherwise. */
enum sb_result sb_json_only_keys(const cJSON *obj, const char *source, const char *section, const char *const *keys);

/* A number in [lo, hi]; logs "source: path: reason" otherwise. */
enum sb_result sb_json_number(const cJSON *item, const char *source, const char *path, double lo, double hi,
                              double *out);

/* An array of three numbers, each in [lo, hi]. */
enum sb_result sb_json_vec3(const cJSON *item, const char *source, const char *path, double lo, double hi,
                            double out[3]);

/* The member `key` of object `obj`, if there, as sb_json_number or
 * sb_json_vec3 would read it, named "where.key" in messages; SB_OK and
 * *out untouched when it is absent (a default stands). */
enum sb_result sb_json_member_number(const cJSON *obj, const char *where, const char *key, double lo, double hi,
                                     const char *source, double *out);
enum sb_result sb_json_member_vec3(const cJSON *obj, const char *where, const char *key, double lo, double hi,
                                   const char *source, double out[3]);

/* A box [[min x, y, z], [max x, y, z]], every coordinate in [lo, hi] and
 * every side at least 0.01 (max above min); `path` names the box. */
enum sb_result sb_json_box(const cJSON *item, const char *source, const char *path, double lo, double hi,
                           double box[2][3]);

#endif
