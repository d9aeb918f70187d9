#include "json.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "log.h"

size_t sb_utf8_check(const char *text, size_t size)
{
    const unsigned char *s = (const unsigned char *)text;
    size_t i = 0;
    while (i < size) {
        unsigned c = s[i];
        if (c < 0x80) {
            i++;
            continue;
        }
        /* the length, and the least value of that length (no overlong forms) */
        size_t n = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
        if (!n || size - i < n)
            return i;
        uint32_t cp = c & (0x7f >> n);
        for (size_t k = 1; k < n; k++) {
            if ((s[i + k] & 0xc0) != 0x80)
                return i;
            cp = cp << 6 | (s[i + k] & 0x3f);
        }
        if ((n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000) || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
            return i;
        i += n;
    }
    return SIZE_MAX;
}

/* Where the text's strings escape a NUL ("\u0000"), which cJSON would
 * silently end the string at; SIZE_MAX for nowhere. */
static size_t find_escaped_nul(const char *text, size_t size)
{
    bool in_string = false;
    for (size_t i = 0; i < size; i++) {
        if (text[i] == '"') {
            in_string = !in_string;
        } else if (in_string && text[i] == '\\' && i + 1 < size) {
            if (text[i + 1] == 'u' && size - i >= 6 && !memcmp(text + i + 2, "0000", 4))
                return i;
            i++; /* the escaped character */
        }
    }
    return SIZE_MAX;
}

static size_t line_of(const char *text, size_t offset)
{
    size_t line = 1;
    for (size_t i = 0; i < offset; i++)
        line += text[i] == '\n';
    return line;
}

enum sb_result sb_json_parse(const char *text, size_t size, const char *source, cJSON **root)
{
    *root = NULL;
    if (size == 0) {
        sb_error("%s: empty file, expected a JSON object", source);
        return SB_ERR_JSON_SYNTAX;
    }
    if (memchr(text, '\0', size)) {
        sb_error("%s: contains a NUL byte: not a JSON text", source);
        return SB_ERR_JSON_SYNTAX;
    }
    /* JSON is UTF-8 (RFC 8259), and what we read we write back into
     * manifests: other bytes would make those invalid. */
    size_t bad = sb_utf8_check(text, size);
    if (bad != SIZE_MAX) {
        sb_error("%s: line %zu: byte %zu is not UTF-8 text", source, line_of(text, bad), bad);
        return SB_ERR_JSON_SYNTAX;
    }
    if ((bad = find_escaped_nul(text, size)) != SIZE_MAX) {
        sb_error("%s: line %zu: a string holds \\u0000 (NUL) at byte %zu, which no name or path may", source,
                 line_of(text, bad), bad);
        return SB_ERR_JSON_SYNTAX;
    }
    const char *end = NULL;
    cJSON *value = cJSON_ParseWithLengthOpts(text, size, &end, false);
    if (!value) {
        size_t offset = end ? (size_t)(end - text) : 0;
        offset = offset < size ? offset : size;
        sb_error("%s: line %zu: malformed JSON near byte %zu", source, line_of(text, offset), offset);
        return SB_ERR_JSON_SYNTAX;
    }
    /* Anything but whitespace after the value is an error. */
    for (const char *c = end; c && c < text + size; c++)
        if (*c != ' ' && *c != '\t' && *c != '\n' && *c != '\r') {
            sb_error("%s: trailing data after the JSON value at byte %zu", source, (size_t)(c - text));
            cJSON_Delete(value);
            return SB_ERR_JSON_SYNTAX;
        }
    *root = value;
    return SB_OK;
}

enum sb_result sb_json_load(int dir, const char *path, const char *source, size_t max_bytes, bool follow_symlinks,
                            cJSON **root)
{
    *root = NULL;
    char *buf;
    size_t n;
    enum sb_result res = sb_read_file(dir, path, source, max_bytes, follow_symlinks, &buf, &n);
    if (res)
        return res;
    res = sb_json_parse(buf, n, source, root);
    free(buf);
    return res;
}

static int compare_keys(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

enum sb_result sb_json_check_duplicates(const cJSON *object, const char *source, const char *where)
{
    /* Sorted, so that an object of many keys costs n log n, not n^2. */
    size_t n = 0;
    for (const cJSON *a = object->child; a; a = a->next)
        n += a->string != NULL;
    if (n < 2)
        return SB_OK;
    const char **keys = malloc(n * sizeof(*keys));
    if (!keys)
        return SB_ERR_NOMEM;
    n = 0;
    for (const cJSON *a = object->child; a; a = a->next)
        if (a->string)
            keys[n++] = a->string;
    qsort(keys, n, sizeof(*keys), compare_keys);
    enum sb_result res = SB_OK;
    for (size_t i = 1; i < n && !res; i++)
        if (!strcmp(keys[i - 1], keys[i])) {
            sb_error("%s: %s%s%s: key given twice", source, where, *where ? "." : "", keys[i]);
            res = SB_ERR_DUPLICATE_KEY;
        }
    free(keys);
    return res;
}

bool sb_json_emit(FILE *out, cJSON *root)
{
    char *text = root ? cJSON_Print(root) : NULL;
    bool ok = text && fprintf(out, "%s\n", text) >= 0;
    free(text);
    cJSON_Delete(root);
    return ok;
}

enum sb_result sb_json_number(const cJSON *item, const char *source, const char *path, double lo, double hi,
                              double *out)
{
    if (!cJSON_IsNumber(item)) {
        sb_error("%s: %s: expected a number", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    if (!isfinite(item->valuedouble) || item->valuedouble < lo || item->valuedouble > hi) {
        sb_error("%s: %s: %.17g is out of range, expected %g to %g", source, path, item->valuedouble, lo, hi);
        return SB_ERR_OUT_OF_RANGE;
    }
    *out = item->valuedouble;
    return SB_OK;
}

enum sb_result sb_json_vec3(const cJSON *item, const char *source, const char *path, double lo, double hi,
                            double out[3])
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3) {
        sb_error("%s: %s: expected an array of 3 numbers", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    char element[160];
    for (int i = 0; i < 3; i++) {
        snprintf(element, sizeof(element), "%s[%d]", path, i);
        enum sb_result res = sb_json_number(cJSON_GetArrayItem(item, i), source, element, lo, hi, &out[i]);
        if (res)
            return res;
    }
    return SB_OK;
}

enum sb_result sb_json_only_keys(const cJSON *obj, const char *source, const char *section, const char *const *keys)
{
    if (!cJSON_IsObject(obj)) {
        sb_error("%s: %s: expected an object", source, section);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = sb_json_check_duplicates(obj, source, section);
    for (const cJSON *item = obj->child; item && !res; item = item->next) {
        bool known = false;
        for (const char *const *k = keys; *k; k++)
            known |= !strcmp(*k, item->string);
        if (!known) {
            sb_error("%s: %s.%s: unknown key (see docs/scene.md)", source, section, item->string);
            res = SB_ERR_UNKNOWN_KEY;
        }
    }
    return res;
}

enum sb_result sb_json_box(const cJSON *item, const char *source, const char *path, double lo, double hi,
                           double box[2][3])
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 2) {
        sb_error("%s: %s: expected [[min x, y, z], [max x, y, z]]", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = SB_OK;
    char corner[160];
    for (int c = 0; c < 2 && !res; c++) {
        snprintf(corner, sizeof(corner), "%s[%d]", path, c);
        res = sb_json_vec3(cJSON_GetArrayItem(item, c), source, corner, lo, hi, box[c]);
    }
    for (int k = 0; k < 3 && !res; k++)
        if (!(box[1][k] - box[0][k] >= 0.01)) {
            sb_error("%s: %s: %g m along %c; a box is at least 0.01 m on every side (max corner above min)", source,
                     path, box[1][k] - box[0][k], "xyz"[k]);
            res = SB_ERR_OUT_OF_RANGE;
        }
    return res;
}

enum sb_result sb_json_member_number(const cJSON *obj, const char *where, const char *key, double lo, double hi,
                                     const char *source, double *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    char path[128];
    snprintf(path, sizeof(path), "%s.%s", where, key);
    return item ? sb_json_number(item, source, path, lo, hi, out) : SB_OK;
}

enum sb_result sb_json_member_vec3(const cJSON *obj, const char *where, const char *key, double lo, double hi,
                                   const char *source, double out[3])
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    char path[128];
    snprintf(path, sizeof(path), "%s.%s", where, key);
    return item ? sb_json_vec3(item, source, path, lo, hi, out) : SB_OK;
}
